"""A vehicle written the usual PyODE way (``import ode``, Debian's python3-pyode), adopted by steadystep in a few
lines.

A chassis on four wheels, each wheel on a hinge-2 joint whose suspension (ERP/CFM) was tuned at 60 fps and whose
motor drives it, runs into 50 crates on the ground: about 200 contacts a step, made by PyODE's
near callback of its tutorials (ode.collide, bounce 0.2, mu 5000, a ContactJoint in a JointGroup emptied after each
step). Its own loop steps one world.quickStep a frame; adopted, steadystep.Stepper steps it (adopt() below: the
stepper takes PyODE's objects as they are, empties PyODE's group through JointGroup.empty(), and makes the contacts
in C from one Contact, the near callback's surface, instead of a Python call per contact).

    python examples/pyode_vehicle.py                              # adopted, implicit-euler, frames of 15 to 45 fps
    python examples/pyode_vehicle.py --loop own --profile fixed:30  # the program's own loop
    python examples/pyode_vehicle.py --policy naive               # bit for bit its own loop, at any frame rate
    python examples/pyode_vehicle.py --contacts near              # its near callback kept: soften_contact in it

Prints CSV t_s,chassis_x_m,chassis_y_m,crates_x_m,crates_y_m (the chassis' position, the crates' mean position)
with full precision: a row at t = 0, then one row a frame. For ``steadystep audit --python``: build_world() and
read_quantities(world) below (and own_frame(world, time_s, frame_s), its own loop).
"""

from __future__ import annotations

import argparse
import sys

import ode

import steadystep as ss
from steadystep.core.pyode import Param  # ODE 0.16's joint parameter numbers: Debian's ode.ParamFMax2 is ODE 0.15's

TUNED_STEP_S = 1.0 / 60.0  # the frame time the program's ERP/CFM were tuned at
WHEEL_SPEED_RAD_S = 10.0   # the motors' target: the car rolls toward +x
CRATE_M = 0.5


class Vehicle:
    """The world as PyODE's examples build one: the objects kept in Python (PyODE destroys what nothing holds)."""

    def __init__(self):
        self.world = ode.World()
        self.world.setGravity((0.0, -9.81, 0.0))
        self.world.setERP(0.2)
        self.world.setCFM(1e-5)
        self.space = ode.HashSpace()
        self.contactgroup = ode.JointGroup()
        self.floor = ode.GeomPlane(self.space, (0.0, 1.0, 0.0), 0.0)
        self.chassis, self.chassis_geom = self._box((2.0, 0.4, 1.0), 200.0, (0.0, 0.75, 0.0))
        self.wheels, self.wheel_geoms, self.joints = [], [], []
        for x in (-0.8, 0.8):
            for z in (-0.65, 0.65):
                wheel = ode.Body(self.world)
                mass = ode.Mass()
                mass.setSphere(1.0, 0.3)  # Debian's PyODE's setSphereTotal takes a density, as setSphere does
                mass.adjust(20.0)
                wheel.setMass(mass)
                wheel.setPosition((x, 0.35, z))
                geom = ode.GeomSphere(self.space, 0.3)
                geom.setBody(wheel)
                joint = ode.Hinge2Joint(self.world)
                joint.attach(self.chassis, wheel)
                joint.setAnchor((x, 0.35, z))
                joint.setAxis2((0.0, 0.0, 1.0))  # the wheel's spin (first: ODE aborts on two parallel axes)
                joint.setAxis1((0.0, 1.0, 0.0))  # steering, held straight by its stops
                joint.setParam(Param.LoStop, 0.0)
                joint.setParam(Param.HiStop, 0.0)
                joint.setParam(Param.SuspensionERP, 0.4)
                joint.setParam(Param.SuspensionCFM, 2e-4)
                joint.setParam(Param.Vel2, WHEEL_SPEED_RAD_S)
                joint.setParam(Param.FMax2, 500.0)
                self.wheels.append(wheel)
                self.wheel_geoms.append(geom)
                self.joints.append(joint)
        self.crates, self.crate_geoms = [], []
        for i in range(10):
            for k in range(5):
                crate, geom = self._box((CRATE_M,) * 3, 4.0, (3.0 + i * (CRATE_M + 0.02), 0.5 * CRATE_M,
                                                              (k - 2) * (CRATE_M + 0.02)))
                self.crates.append(crate)
                self.crate_geoms.append(geom)

    def _box(self, lengths, mass_kg, position):
        body = ode.Body(self.world)
        mass = ode.Mass()
        mass.setBoxTotal(mass_kg, *lengths)
        body.setMass(mass)
        body.setPosition(position)
        geom = ode.GeomBox(self.space, lengths)
        geom.setBody(body)
        return body, geom

    def quantities(self) -> dict:
        x, y, _ = self.chassis.getPosition()
        crates = [crate.getPosition() for crate in self.crates]
        return {"chassis_x_m": x, "chassis_y_m": y, "crates_x_m": sum(p[0] for p in crates) / len(crates),
                "crates_y_m": sum(p[1] for p in crates) / len(crates)}


def near_callback(args, geom1, geom2):
    """The near callback of PyODE's tutorials; with a stepper, each contact softened for the step first."""
    vehicle, stepper = args
    for contact in ode.collide(geom1, geom2):
        contact.setBounce(0.2)
        contact.setMu(5000)
        if stepper is not None:
            stepper.soften_contact(contact, geom1.getBody(), geom2.getBody())
        joint = ode.ContactJoint(vehicle.world, vehicle.contactgroup, contact)
        joint.attach(geom1.getBody(), geom2.getBody())


def own_step(vehicle: Vehicle, frame_s: float) -> None:
    """The program's own loop: one step of the frame's length, as PyODE's examples step."""
    vehicle.space.collide((vehicle, None), near_callback)
    vehicle.world.quickStep(frame_s)
    vehicle.contactgroup.empty()


def surface() -> ode.Contact:
    """What near_callback gives every contact, as one Contact."""
    contact = ode.Contact()
    contact.setBounce(0.2)
    contact.setMu(5000)
    return contact


def adopt(vehicle: Vehicle, policy: str, contacts: str = "rule") -> ss.Stepper:
    """The program adopted: its world, space and joint group as they are, its contacts by rule (or its near
    callback, softening each contact)."""
    if contacts == "rule":  # PyODE's ode.collide asks dCollide for 150 contacts a pair
        made = {"contact_rule": ss.ContactRule(surface(), max_contacts=150)}
    else:
        made = {"collide": lambda stepper: vehicle.space.collide((vehicle, stepper), near_callback)}
    return ss.Stepper(vehicle.world, space=vehicle.space, tuned_step_s=TUNED_STEP_S, solver=ss.Solver.QUICK,
                      policy=policy, contact_group=vehicle.contactgroup, **made)


# ---- steadystep audit --python examples/pyode_vehicle.py ---------------------------------------------------------

def build_world():
    """The audit's PythonWorld: the vehicle, its contacts by rule (stepper.collide_by_rule) in PyODE's group."""
    from steadystep.audit import PythonWorld

    vehicle = Vehicle()
    rule = ss.ContactRule(surface(), max_contacts=150)
    return PythonWorld(world=vehicle.world, space=vehicle.space, tuned_step_s=TUNED_STEP_S,
                       collide=lambda stepper: stepper.collide_by_rule(rule), contact_group=vehicle.contactgroup,
                       extra={"vehicle": vehicle})


def read_quantities(world) -> dict:
    return world.extra["vehicle"].quantities()


def own_frame(world, time_s: float, frame_s: float) -> None:
    """The audit's "own" variant: a frame of the program's own loop."""
    own_step(world.extra["vehicle"], frame_s)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loop", choices=("adopted", "own"), default="adopted", help="default adopted")
    parser.add_argument("--policy", default="implicit-euler", choices=ss.policy_names(),
                        help="adopted: how frames become steps (default implicit-euler)")
    parser.add_argument("--contacts", choices=("rule", "near"), default="rule",
                        help="adopted: a ContactRule (default), or the near callback with soften_contact")
    parser.add_argument("--profile", default="uniform:15:45", help="frame-time profile (default uniform:15:45)")
    parser.add_argument("--seed", type=int, default=1, help="the profile's seed (default 1)")
    parser.add_argument("--duration", type=float, default=5.0, help="simulated seconds (default 5)")
    args = parser.parse_args(argv)

    vehicle = Vehicle()
    stepper = adopt(vehicle, args.policy, args.contacts) if args.loop == "adopted" else None
    names = list(vehicle.quantities())
    print(",".join(["t_s", *names]))
    time_s = 0.0
    print(",".join(repr(v) for v in (time_s, *vehicle.quantities().values())))
    for frame_s in ss.lab.profiles.frames_within(args.profile, args.duration, args.seed):
        if stepper is None:
            own_step(vehicle, frame_s)
            time_s += frame_s
        else:
            time_s = stepper.step(frame_s).time_s
        print(",".join(repr(v) for v in (time_s, *vehicle.quantities().values())))
    if stepper is not None:
        stepper.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
