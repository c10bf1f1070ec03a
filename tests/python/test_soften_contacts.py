"""Stepper.soften_contacts on real ODE (odepy): one call for a dCollide result softens every contact as
Stepper.soften_contact softens each, byte for byte, and a refused batch names the value and leaves every contact as
the program gave it."""

import ctypes
import math
import random

import odepy
import pytest

import steadystep as ss


pytestmark = pytest.mark.usefixtures("odepy_initialised")


@pytest.fixture
def adopted():
    """An adopted world of boxes resting on a plane, tuned at 1/60 s; yields (world, space, group, stepper), the
    stepper under implicit Euler with steps of at most 1/120 s: between frames it softens for its next step, 1/120 s,
    where implicit Euler rewrites every contact's tuned softness."""
    world = odepy.dWorldCreate()
    odepy.dWorldSetGravity(world, 0.0, 0.0, -9.81)
    space = odepy.dHashSpaceCreate(0)
    group = odepy.dJointGroupCreate(0)
    odepy.dCreatePlane(space, 0.0, 0.0, 1.0, 0.0)
    for i in range(6):
        box = odepy.dBodyCreate(world)
        mass = odepy.dMass()
        odepy.dMassSetBoxTotal(ctypes.byref(mass), 1.0, 0.2, 0.2, 0.2)
        odepy.dBodySetMass(box, ctypes.byref(mass))
        odepy.dBodySetPosition(box, 0.5 * i, 0.0, 0.099)  # already touching: contacts in the first step
        odepy.dGeomSetBody(odepy.dCreateBox(space, 0.2, 0.2, 0.2), box)
    registry = ss.Registry(world)
    registry.adopt(1 / 60, space)
    stepping = ss.Stepping.for_policy("implicit-euler", max_step_s=1 / 120, solver=ss.Solver.QUICK)
    stepper = ss.Stepper(world, registry, stepping=stepping)
    yield world, space, group, stepper
    stepper.close()
    odepy.dJointGroupDestroy(group)
    odepy.dSpaceDestroy(space)
    odepy.dWorldDestroy(world)


def made_contacts(count, seed):
    """count contacts as a near callback fills them: one surface (soft ERP and CFM as tuned), geometry at random."""
    rng = random.Random(seed)
    contacts = (odepy.dContact * count)()
    for contact in contacts:
        contact.surface.mode = odepy.dContactSoftERP | odepy.dContactSoftCFM | odepy.dContactApprox1
        contact.surface.mu = 0.8
        contact.surface.soft_erp = 0.2
        contact.surface.soft_cfm = 1e-5
        for axis in range(3):
            contact.geom.pos[axis] = rng.uniform(-10, 10)
        contact.geom.normal[2] = 1.0
        contact.geom.depth = rng.uniform(0, 0.01)
    return contacts


def raw(contacts, count):
    return ctypes.string_at(ctypes.addressof(contacts), count * ctypes.sizeof(odepy.dContact))


def test_a_batch_is_softened_as_each_contact_alone_byte_for_byte(adopted):
    """In the near callback of frames of 1/120 s, where implicit Euler rewrites every contact's tuned softness."""
    world, space, group, _ = adopted
    pairs = []

    def near(data, g1, g2):
        contacts = (odepy.dContact * 4)()
        for contact in contacts:
            contact.surface.mode = odepy.dContactSoftERP | odepy.dContactSoftCFM | odepy.dContactApprox1
            contact.surface.mu = 0.8
            contact.surface.soft_erp = 0.2
            contact.surface.soft_cfm = 1e-5
        count = odepy.dCollide(g1, g2, 4, ctypes.byref(contacts[0].geom), ctypes.sizeof(odepy.dContact))
        alone = (odepy.dContact * 4)()
        ctypes.memmove(alone, contacts, ctypes.sizeof(contacts))
        b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
        for i in range(count):
            stepper.soften_contact(alone[i], b1, b2)
        stepper.soften_contacts(contacts, count)
        pairs.append((count, raw(contacts, count) == raw(alone, count), contacts[0].surface.soft_erp))
        for i in range(count):
            odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contacts[i])), b1, b2)

    callback = odepy.dNearCallback(near)
    registry = adopted[3].registry
    adopted[3].close()  # the world's stepper is this one
    stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, policy="implicit-euler",
                         contact_group=group, collide=lambda s: odepy.dSpaceCollide(space, None, callback))
    for _ in range(5):
        stepper.step(1 / 120)
    stepper.close()
    assert len(pairs) >= 5 * 6 and all(count == 4 for count, _, _ in pairs)
    assert all(same for _, same, _ in pairs)
    # the softness was written for 1/120 s: implicit Euler's, not the tuned 0.2
    k, c = 0.2 / (1 / 60 * 1e-5), (1 - 0.2) / 1e-5
    assert all(math.isclose(erp, k / 120 / (k / 120 + c), rel_tol=1e-12) for _, _, erp in pairs)


@pytest.mark.parametrize("seed", range(20))
def test_random_batches_match_each_contact_alone(adopted, seed):
    stepper = adopted[3]
    count = 1 + seed % 8
    batch, alone = made_contacts(count, seed), made_contacts(count, seed)
    if seed % 3 == 0:  # a surface of its own in the middle: the batch takes the slow path
        batch[count // 2].surface.soft_cfm = alone[count // 2].surface.soft_cfm = 3e-4
    for contact in alone:
        stepper.soften_contact(contact, None, None)
    stepper.soften_contacts(batch, count)
    assert raw(batch, count) == raw(alone, count)
    assert batch[0].surface.soft_erp != 0.2  # written for 1/120 s


def test_a_refused_batch_names_the_contact_and_leaves_every_contact_as_given(adopted):
    stepper = adopted[3]
    contacts = made_contacts(4, 7)
    contacts[2].geom.normal[0] = math.nan  # ODE's own sphere-cylinder NaN normal, which aborts its step
    given = raw(contacts, 4)
    with pytest.raises(ss.SteadystepError, match=r"normal not finite .*normal \(nan, 0, 1\)") as refused:
        stepper.soften_contacts(contacts, 4)
    assert refused.value.code == ss.Status.NOT_FINITE
    assert raw(contacts, 4) == given
    stepper.soften_contacts(contacts, 2)  # the two before it are good
    assert contacts[0].surface.soft_erp != 0.2


@pytest.mark.parametrize("count, message", [(5, "count = 5: more than the 4 contacts"), (-1, "count = -1"),
                                            (True, "count = True"), (2.0, "count = 2.0"),
                                            (2**40, "count = 1099511627776")])
def test_a_bad_count_is_refused_by_name_with_the_contacts_as_given(adopted, count, message):
    stepper = adopted[3]
    contacts = made_contacts(4, 3)
    given = raw(contacts, 4)
    with pytest.raises(ss.SteadystepError, match=message.replace("(", r"\(")):
        stepper.soften_contacts(contacts, count)
    assert raw(contacts, 4) == given


def test_no_contacts_is_nothing_to_do_and_a_wrong_array_is_refused(adopted):
    stepper = adopted[3]
    stepper.soften_contacts(made_contacts(1, 0), 0)
    with pytest.raises(ss.SteadystepError, match="array of c_double, not of dContact"):
        stepper.soften_contacts((ctypes.c_double * 4)(), 1)
    with pytest.raises(ss.SteadystepError, match="contacts = NULL with count = 1"):
        stepper.soften_contacts(None, 1)


def test_a_pyode_contact_is_one_contact(adopted):
    ode = pytest.importorskip("ode")
    stepper = adopted[3]
    contact = ode.Contact()
    contact.setMode(ode.ContactSoftERP | ode.ContactSoftCFM)
    contact.setSoftERP(0.2)
    contact.setSoftCFM(1e-5)
    with pytest.raises(ss.SteadystepError, match="a PyODE Contact holds one contact, not count = 2"):
        stepper.soften_contacts(contact, 2)
    assert contact.getSoftERP() == 0.2
    stepper.soften_contacts(contact, 1)
    k, c = 0.2 / (1 / 60 * 1e-5), (1 - 0.2) / 1e-5
    assert math.isclose(contact.getSoftERP(), k / 120 / (k / 120 + c), rel_tol=1e-12)
