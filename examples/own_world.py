"""The article's oscillator, built the usual ODE way with odepy (PyPI ode-python), stepped through steadystep.

One body of 1 kg on a slider whose stop (lo = hi = 0) is a spring of k = 40 N/m and c = 1 N·s/m, no gravity,
released at rest from x0 = 0.5 m, for 5 s of frames drawn from the lab profile uniform:15:45 (seed 1), under the
exact policy (substeps of at most 1/60 s). Prints CSV t,x,v (s, m, m/s) with full precision: a row at t = 0, then
one row after every physics step (the stepper's step_done callback). Under the exact mapping x follows the exact
damped-oscillator solution (tests/python/test_own_world.py checks it to 1e-9 m).

    .venv/bin/python examples/own_world.py > own_world.csv
    .venv/bin/python examples/own_world.py --policy implicit-euler --profile fixed:30
"""

from __future__ import annotations

import argparse
import ctypes
import sys

import odepy

import steadystep as ss

MASS_KG = 1.0
SPRING = ss.Spring(stiffness=40.0, damping=1.0)  # N/m, N·s/m
X0_M = 0.5


def build(world):
    """The body on its slider along x, with the stop at x = 0; the body is moved to x0 once the slider has taken
    x = 0 as its origin."""
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), MASS_KG, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    slider = odepy.dJointCreateSlider(world, 0)
    odepy.dJointAttach(slider, body, 0)
    odepy.dJointSetSliderAxis(slider, 1.0, 0.0, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamLoStop, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamHiStop, 0.0)
    odepy.dBodySetPosition(body, X0_M, 0.0, 0.0)
    return body, slider


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", default="uniform:15:45", help="frame-time profile (default uniform:15:45)")
    parser.add_argument("--seed", type=int, default=1, help="the profile's seed (default 1)")
    parser.add_argument("--policy", default="exact", choices=ss.policy_names(), help="default exact")
    parser.add_argument("--duration", type=float, default=5.0, help="simulated seconds (default 5)")
    args = parser.parse_args(argv)

    odepy.dInitODE2(0)
    odepy.dRandSetSeed(1)  # QuickStep shuffles rows with ODE's global generator: the same run every time
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)
    body, slider = build(world)

    registry = ss.Registry(world)
    registry.bind_joint(slider, ss.JointParam.STOP, 1, SPRING)  # effective mass from the body: 1 kg

    out = sys.stdout
    time_s = 0.0

    def record(step_s: float) -> None:
        nonlocal time_s
        time_s += step_s
        out.write(f"{time_s!r},{odepy.dBodyGetPosition(body)[0]!r},{odepy.dBodyGetLinearVel(body)[0]!r}\n")

    stepper = ss.Stepper(world, registry, policy=args.policy, solver=ss.Solver.QUICK, tuned_step_s=1 / 60,
                         step_done=record)
    out.write("t,x,v\n")
    out.write(f"0.0,{odepy.dBodyGetPosition(body)[0]!r},{odepy.dBodyGetLinearVel(body)[0]!r}\n")
    profile = ss.Profile(args.profile, args.seed)
    elapsed_s = 0.0
    end_tolerance_s = 1e-9 * max(1.0, args.duration)  # a rounding remainder is the end, not one more frame
    while args.duration - elapsed_s > end_tolerance_s:
        frame_s = min(profile.next(), args.duration - elapsed_s)
        stepper.step(frame_s)
        elapsed_s += frame_s

    stepper.close()
    registry.close()
    odepy.dWorldDestroy(world)
    odepy.dCloseODE()
    return 0


if __name__ == "__main__":
    sys.exit(main())
