"""Issue 28: a Python program whose near callback forgets Stepper.soften_contact is counted, frame by frame, in the
audit's unsoftened_contact_steps column (the frame report's count), and one that softens its contacts is not. The
audit's claim about it is tested on a C program (test_audit_programs.py, box_stack_unsoftened)."""

import numpy as np
import pytest

from steadystep import audit
from steadystep.audit.run import STEP_COLUMN, UNSOFTENED_COLUMN, run

PROGRAM = '''
import ctypes

import odepy

import steadystep as ss
from steadystep.audit import PythonWorld

SOFTEN = True


def build_world():
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, -9.81)
    space = odepy.dSimpleSpaceCreate(0)
    group = odepy.dJointGroupCreate(0)
    odepy.dCreatePlane(space, 0.0, 0.0, 1.0, 0.0)
    ball = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetSphereTotal(ctypes.byref(mass), 1.0, 0.1)
    odepy.dBodySetMass(ball, ctypes.byref(mass))
    odepy.dBodySetPosition(ball, 0.0, 0.0, 0.3)
    odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), ball)
    state = {}

    def near(data, g1, g2):
        contacts = (odepy.dContact * 4)()
        count = odepy.dCollide(g1, g2, 4, ctypes.byref(contacts[0].geom), ctypes.sizeof(odepy.dContact))
        b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
        for i in range(count):
            contacts[i].surface.mode = 0
            contacts[i].surface.mu = 1.0
            if SOFTEN:
                state["stepper"].soften_contact(contacts[i], b1, b2)
            odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contacts[i])), b1, b2)

    callback = odepy.dNearCallback(near)

    def collide(stepper):
        state["stepper"] = stepper
        odepy.dSpaceCollide(space, None, callback)

    def close():
        odepy.dJointGroupDestroy(group)
        odepy.dSpaceDestroy(space)
        odepy.dWorldDestroy(world)

    return PythonWorld(world=world, space=space, collide=collide, contact_group=group, close=close,
                       extra={"ball": ball, "callback": callback})


def read_quantities(world):
    return {"z_m": odepy.dBodyGetPosition(world.extra["ball"])[2]}
'''


@pytest.mark.parametrize("soften", [True, False])
def test_steps_with_contacts_none_softened_are_counted(tmp_path, soften):
    path = tmp_path / "ball.py"
    path.write_text(PROGRAM.replace("SOFTEN = True", f"SOFTEN = {soften}"))
    made = run(audit.PythonProgram(str(path)), "implicit-euler", "uniform:15:45", 1, 1.0)
    assert made.ok, made.status
    unsoftened, softened = made.columns[UNSOFTENED_COLUMN], made.columns["contacts_by_mapping"]
    assert made.columns["z_m"][-1] < 0.101  # it fell and rests on the plane: contacts every step from then on
    if soften:
        assert softened.sum() > 0 and not unsoftened.any()
    else:
        assert not softened.any()
        # every step after the first touch is counted: at most a frame's steps, and all of them once it rests
        assert 0 < unsoftened.sum() <= made.columns[STEP_COLUMN].sum()
        assert np.array_equal(unsoftened[-10:], made.columns[STEP_COLUMN][-10:])
