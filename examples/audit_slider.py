"""A Python program taking part in `steadystep audit` (docs/audit.md): it hands over a function that builds its odepy
world and one that reads its quantities; the audit steps the world itself under every profile and policy.

A 1 kg body on a slider whose stop (lo = hi = 0) is a spring of k = 40 N/m, c = 1 N·s/m (the article's kind),
released at rest from x0 = 0.5 m with no gravity, and pushed by the program's per-step logic (a force of
2 N·sin(2π t / 1.7 s), t the simulated time at each physics step's start): an input that changes with time is
computed before every step, not once a frame, so that under the fixed policies the motion is the same at every
frame rate.

Its own stepping (own_frame), as a program without the library writes it: the stop's ERP and CFM as the spring's at
the 60 fps step it was tuned for, the push once a frame, one dWorldQuickStep of the frame.

    .venv/bin/steadystep audit --python examples/audit_slider.py --out audit-slider
"""

from __future__ import annotations

import ctypes
import math

import odepy

import steadystep as ss
from steadystep.audit import PythonWorld

MASS_KG = 1.0
SPRING = ss.Spring(stiffness=40.0, damping=1.0)  # N/m, N·s/m
X0_M = 0.5
TUNED_STEP_S = 1.0 / 60.0


def push_n(time_s: float) -> float:
    """The program's input at time_s (s): a force along x (N)."""
    return 2.0 * math.sin(2 * math.pi * time_s / 1.7)


def build_world() -> PythonWorld:
    """The world, its body on a slider along x with the stop at x = 0, the spring bound in a registry."""
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), MASS_KG, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    slider = odepy.dJointCreateSlider(world, 0)
    odepy.dJointAttach(slider, body, 0)
    odepy.dJointSetSliderAxis(slider, 1.0, 0.0, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamLoStop, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamHiStop, 0.0)
    odepy.dBodySetPosition(body, X0_M, 0.0, 0.0)  # after the slider took x = 0 as its origin
    registry = ss.Registry(world)
    registry.bind_joint(slider, ss.JointParam.STOP, 1, SPRING)  # effective mass from the body: 1 kg

    def push(time_s: float, step_s: float) -> None:  # before every physics step: its start time and length (s)
        odepy.dBodyAddForce(body, push_n(time_s), 0.0, 0.0)

    def close() -> None:
        registry.close()
        odepy.dWorldDestroy(world)

    return PythonWorld(world=world, registry=registry, before_step=push, close=close,
                       extra={"body": body, "slider": slider})


def own_frame(world: PythonWorld, time_s: float, frame_s: float) -> None:
    """One frame of the program's own stepping, without the library: the stop's ERP and CFM as tuned at 60 fps
    (the article's erp = hk / (hk + c), cfm = 1 / (hk + c) at h = 1/60 s), the push once a frame, one QuickStep."""
    h, k, c = TUNED_STEP_S, SPRING.stiffness, SPRING.damping
    slider = world.extra["slider"]
    odepy.dJointSetSliderParam(slider, odepy.dParamStopERP, h * k / (h * k + c))
    odepy.dJointSetSliderParam(slider, odepy.dParamStopCFM, 1.0 / (h * k + c))
    odepy.dBodyAddForce(world.extra["body"], push_n(time_s), 0.0, 0.0)
    odepy.dWorldQuickStep(world.world, frame_s)


def read_quantities(world: PythonWorld) -> dict[str, float]:
    """The body's position and velocity along the slider (m, m/s), named with their units."""
    body = world.extra["body"]
    return {"x_m": odepy.dBodyGetPosition(body)[0], "v_m_per_s": odepy.dBodyGetLinearVel(body)[0]}
