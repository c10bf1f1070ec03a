"""The core on a world the test builds itself with odepy (PyPI ode-python), on real ODE: adoption, bindings read
back with odepy's getters, stepping under every policy against independent recurrences and the exact solution,
forces kept over a frame, contacts softened in an odepy near callback, refusals, callback exceptions and reset.

The truths are stated here, not taken from the library: k = erp/(h0·cfm), c = (1 - erp)/cfm and
erp = hk/(hk+c), cfm = 1/(hk+c) for the article's mapping; the implicit-Euler step of m x'' = -k x - c v;
the closed form of the damped oscillator; momentum F·t.
"""

import ctypes
import gc
import math

import numpy as np
import odepy
import pytest

import steadystep as ss

K, C, M, X0 = 40.0, 1.0, 1.0, 0.5  # N/m, N·s/m, kg, m: the article's oscillator


@pytest.fixture(scope="module", autouse=True)
def ode():
    odepy.dInitODE2(0)
    yield  # dCloseODE is left to the process: other modules may still hold worlds


@pytest.fixture
def world():
    made = odepy.dWorldCreate()
    odepy.dWorldSetGravity(made, 0.0, 0.0, 0.0)
    odepy.dRandSetSeed(1)
    yield made
    odepy.dWorldDestroy(made)


def address(handle) -> int:
    return ctypes.cast(handle, ctypes.c_void_p).value


def box_body(world, mass_kg=M, x=0.0):
    body = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetBoxTotal(ctypes.byref(mass), mass_kg, 0.1, 0.1, 0.1)
    odepy.dBodySetMass(body, ctypes.byref(mass))
    odepy.dBodySetPosition(body, x, 0.0, 0.0)
    return body


def oscillator(world):
    """1 kg on a slider along x to the static world, its stop at x = 0 (lo = hi = 0), released from X0."""
    body = box_body(world)
    slider = odepy.dJointCreateSlider(world, 0)
    odepy.dJointAttach(slider, body, 0)
    odepy.dJointSetSliderAxis(slider, 1.0, 0.0, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamLoStop, 0.0)
    odepy.dJointSetSliderParam(slider, odepy.dParamHiStop, 0.0)
    odepy.dBodySetPosition(body, X0, 0.0, 0.0)
    return body, slider


def exact_x(t):
    a = C / (2 * M)
    w = math.sqrt(K / M - a * a)
    return np.exp(-a * t) * (X0 * np.cos(w * t) + a * X0 / w * np.sin(w * t))


def implicit_euler(steps, k, c, m=M, x=X0, v=0.0):
    """x after each step of the implicit-Euler recurrence m(v' - v)/h = -k(x + h v') - c v', x' = x + h v'
    (k and c may be functions of h)."""
    out = []
    for h in steps:
        kh = k(h) if callable(k) else k
        ch = c(h) if callable(c) else c
        v = (m * v - h * kh * x) / (m + h * ch + h * h * kh)
        x = x + h * v
        out.append(x)
    return np.array(out)


def frames(spec="uniform:15:45", duration_s=2.0, seed=1):
    profile = ss.Profile(spec, seed)
    out, elapsed = [], 0.0
    while duration_s - elapsed > 1e-9:
        out.append(min(profile.next(), duration_s - elapsed))
        elapsed += out[-1]
    return out


# ---- adoption and bindings, read back with odepy ------------------------------------------------------------

def test_adopting_an_odepy_world_binds_what_it_tuned_and_rewrites_it_for_each_step(world):
    space = odepy.dSimpleSpaceCreate(0)
    erp0, cfm0, h0 = 0.3, 1e-5, 1.0 / 60
    odepy.dWorldSetERP(world, erp0)
    odepy.dWorldSetCFM(world, cfm0)
    bodies = []
    for i in range(2):
        body = box_body(world, x=float(i))
        odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), body)
        bodies.append(body)
    ball = odepy.dJointCreateBall(world, 0)  # copies the world's ERP/CFM now: the adopted row is (erp0, cfm0)
    odepy.dJointAttach(ball, bodies[0], bodies[1])
    hinge = odepy.dJointCreateHinge(world, 0)
    odepy.dJointAttach(hinge, bodies[1], 0)
    odepy.dJointSetHingeParam(hinge, odepy.dParamStopERP, 0.5)
    odepy.dJointSetHingeParam(hinge, odepy.dParamStopCFM, 1e-4)

    registry = ss.Registry(world)
    report = registry.adopt(h0, space)
    assert report == ss.AdoptReport(world=1, joints=2, joint_rows=1, stop_rows=1, motor_rows=1, suspension_rows=0,
                                    hard_rows=0, bodies=2, skipped_joints=0)
    assert registry.tuned_step_s == h0 and registry.joint_binding_count == 3
    again = registry.adopt(h0, space)  # idempotent: nothing bound twice
    assert (again.world, again.joint_rows, again.stop_rows, again.motor_rows) == (0, 0, 0, 0)
    assert registry.joint_binding_count == 3

    def softness(erp, cfm, h):  # the spring the tuned row stands for, at step h (the article's mapping)
        k, c = erp / (h0 * cfm), (1 - erp) / cfm
        return h * k / (h * k + c), 1 / (h * k + c)

    for h in (h0, 1 / 30, 1 / 144, 0.1):
        applied = registry.apply(h, ss.Mapping.IMPLICIT_EULER)
        assert applied.rows == ss.ServedCounts(4, 0, 0)  # the world and the three joint rows, once each
        # written where the softness changed with the step: not the motor's cfm = 1/c (a damper: k = 0)
        assert applied.row_writes == 3 or h == h0
        assert (odepy.dWorldGetERP(world), odepy.dWorldGetCFM(world)) == pytest.approx(softness(erp0, cfm0, h),
                                                                                       rel=1e-12)
        assert (odepy.dJointGetBallParam(ball, odepy.dParamERP), odepy.dJointGetBallParam(ball, odepy.dParamCFM)
                ) == pytest.approx(softness(erp0, cfm0, h), rel=1e-12)
        assert (odepy.dJointGetHingeParam(hinge, odepy.dParamStopERP),
                odepy.dJointGetHingeParam(hinge, odepy.dParamStopCFM)) == pytest.approx(softness(0.5, 1e-4, h),
                                                                                        rel=1e-12)
    odepy.dSpaceDestroy(space)


def test_bound_springs_are_read_back_from_odes_joint_and_world(world):
    body, slider = oscillator(world)
    registry = ss.Registry(address(world))  # a plain address works as the handle does
    registry.bind_joint(slider, ss.JointParam.STOP, 1, ss.Spring(K, C))
    registry.bind_world(ss.Spring(100.0, 2.0))
    assert ss.joint_supports(slider, ss.JointParam.STOP, 1) and not ss.joint_supports(slider, ss.JointParam.JOINT, 1)
    assert ss.joint_effective_mass(slider, ss.JointParam.STOP, 1) == pytest.approx(M, rel=1e-12)
    for h in np.linspace(1e-3, 0.2, 7):
        registry.apply(h)
        assert odepy.dJointGetSliderParam(slider, odepy.dParamStopERP) == pytest.approx(h * K / (h * K + C), rel=1e-12)
        assert odepy.dJointGetSliderParam(slider, odepy.dParamStopCFM) == pytest.approx(1 / (h * K + C), rel=1e-12)
        assert odepy.dWorldGetERP(world) == pytest.approx(h * 100 / (h * 100 + 2), rel=1e-12)
    # A refused binding changes nothing: the joint's softness stays as the last apply wrote it.
    before = odepy.dJointGetSliderParam(slider, odepy.dParamStopERP)
    with pytest.raises(ss.SteadystepError, match="k = -1"):
        registry.bind_joint(slider, ss.JointParam.STOP, 1, ss.Spring(-1.0, C))
    registry.apply(0.2)
    assert odepy.dJointGetSliderParam(slider, odepy.dParamStopERP) == before


# ---- stepping ---------------------------------------------------------------------------------------------------

def run_oscillator(world, policy, frame_list, **stepping):
    body, slider = oscillator(world)
    registry = ss.Registry(world)
    registry.bind_joint(slider, ss.JointParam.STOP, 1, ss.Spring(K, C))
    steps, xs, reports = [], [], []

    def done(step_s):
        steps.append(step_s)
        xs.append(odepy.dBodyGetPosition(body)[0])

    stepping = {"max_step_s": 1 / 60, "fixed_step_s": 1 / 60, "solver": ss.Solver.QUICK, **stepping}
    base = ss.Stepping.for_policy(policy, 1 / 30, **stepping)
    stepper = ss.Stepper(world, registry, stepping=base, step_done=done)
    for frame_s in frame_list:
        reports.append(stepper.step(frame_s))
    stepper.close()
    return np.array(steps), np.array(xs), reports


@pytest.mark.parametrize("policy", ss.policy_names())
def test_every_policy_steps_an_odepy_world_as_its_truth_says(world, policy):
    frame_list = frames(duration_s=2.0)
    steps, xs, reports = run_oscillator(world, policy, frame_list, solver=ss.Solver.STEP)
    times = np.cumsum(steps)
    stepping = ss.Stepping.for_policy(policy, 1 / 30, max_step_s=1 / 60, fixed_step_s=1 / 60)
    assert sum(r.steps for r in reports) == len(steps)
    assert sum(r.simulated_s for r in reports) == pytest.approx(times[-1], abs=1e-12)
    if stepping.cut == ss.FrameCut.SUBSTEPS:
        assert [r.steps for r in reports] == [math.ceil(f / stepping.max_step_s - 1e-12) for f in frame_list]
    elif stepping.cut == ss.FrameCut.WHOLE_FRAME:
        assert list(steps) == pytest.approx(frame_list, rel=1e-15)
    else:
        assert np.allclose(steps, stepping.fixed_step_s, rtol=1e-15)
    if stepping.mapping == ss.Mapping.EXACT:
        assert np.max(np.abs(xs - exact_x(times))) < 1e-9 * X0
    elif stepping.frozen_step_s > 0:  # naive: ERP/CFM frozen at 1/30 s stand for k' = erp/(h cfm) at each h
        h_r = stepping.frozen_step_s
        erp, cfm = h_r * K / (h_r * K + C), 1 / (h_r * K + C)
        truth = implicit_euler(steps, lambda h: erp / (h * cfm), lambda h: (1 - erp) / cfm)
        assert np.max(np.abs(xs - truth)) < 1e-9 * X0
    elif stepping.mapping == ss.Mapping.IMPLICIT_EULER:
        assert np.max(np.abs(xs - implicit_euler(steps, K, C))) < 1e-9 * X0
    else:  # matched: over two equal steps of h, x obeys the recurrence whose poles are the exact exp(s·h)
        a, w = C / (2 * M), math.sqrt(K / M - (C / (2 * M)) ** 2)
        path = np.concatenate(([X0], xs))  # path[i + 1] is after steps[i]; ODE's velocity is the last slope
        checked = 0
        for i in range(1, len(steps)):
            if steps[i] == pytest.approx(steps[i - 1], rel=1e-12):
                h = steps[i]
                s_sum, p_product = 2 * math.exp(-a * h) * math.cos(w * h), math.exp(-C * h / M)
                assert path[i + 1] - s_sum * path[i] + p_product * path[i - 1] == pytest.approx(0, abs=1e-9 * X0)
                checked += 1
        assert checked > len(steps) / 3


def test_the_example_follows_the_exact_solution(tmp_path):
    import subprocess
    import sys
    from pathlib import Path
    example = Path(__file__).resolve().parents[2] / "examples" / "own_world.py"
    out = subprocess.run([sys.executable, str(example)], capture_output=True, text=True, check=True).stdout
    lines = out.splitlines()
    assert lines[0] == "t,x,v" and lines[1] == "0.0,0.5,0.0"
    t, x, v = np.array([[float(value) for value in line.split(",")] for line in lines[1:]]).T
    assert t[-1] == pytest.approx(5.0, abs=1e-12) and np.all(np.diff(t) > 0) and np.all(np.diff(t) <= 1 / 60 + 1e-15)
    assert np.max(np.abs(x - exact_x(t))) < 1e-9
    # ODE's velocity after a step is the slope over it (x' = x + h v'), whatever the mapping.
    assert np.allclose(v[1:], np.diff(x) / np.diff(t), rtol=0, atol=1e-9)


@pytest.mark.parametrize("policy", ["naive", "implicit-euler", "exact", "fixed"])
def test_a_force_added_once_a_frame_delivers_f_dt(world, policy):
    body = box_body(world, mass_kg=2.0)
    stepper = ss.Stepper(world, None, policy=policy, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    stepper.watch_body(body)
    force, total = 3.0, 0.0
    for frame_s in frames(duration_s=1.0):  # frames of 1/45 to 1/15 s: every frame takes a step, also under fixed
        odepy.dBodyAddForce(body, force, 0.0, 0.0)
        total += stepper.step(frame_s).simulated_s
    assert odepy.dBodyGetLinearVel(body)[0] * 2.0 == pytest.approx(force * total, rel=1e-12)
    stepper.close()


def test_contacts_are_softened_in_an_odepy_near_callback(world):
    space = odepy.dSimpleSpaceCreate(0)
    group = odepy.dJointGroupCreate(0)
    odepy.dWorldSetGravity(world, 0.0, 0.0, -9.81)
    erp0, cfm0, h0 = 0.2, 1e-5, 1 / 60
    odepy.dWorldSetERP(world, erp0)
    odepy.dWorldSetCFM(world, cfm0)
    odepy.dCreatePlane(space, 0.0, 0.0, 1.0, 0.0)
    ball = odepy.dBodyCreate(world)
    mass = odepy.dMass()
    odepy.dMassSetSphereTotal(ctypes.byref(mass), M, 0.1)
    odepy.dBodySetMass(ball, ctypes.byref(mass))
    odepy.dBodySetPosition(ball, 0.0, 0.0, 0.1)
    odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), ball)
    registry = ss.Registry(world)
    registry.adopt(h0, space)
    k, c = erp0 / (h0 * cfm0), (1 - erp0) / cfm0
    seen = []

    def near(data, g1, g2):
        contacts = (odepy.dContact * 4)()
        count = odepy.dCollide(g1, g2, 4, ctypes.byref(contacts[0].geom), ctypes.sizeof(odepy.dContact))
        b1, b2 = odepy.dGeomGetBody(g1), odepy.dGeomGetBody(g2)
        for i in range(count):
            contacts[i].surface.mode = 0  # the world's ERP/CFM, as tuned
            contacts[i].surface.mu = 1.0
            # the odepy contact as it is, or its address (and the bodies' addresses) in every other step
            if len(seen) % 2:
                stepper.soften_contact(ctypes.addressof(contacts[i]), address(b1), address(b2) or 0)
            else:
                stepper.soften_contact(contacts[i], b1, b2)
            h = stepper.current_step().step_s
            seen.append((contacts[i].surface.soft_erp, contacts[i].surface.soft_cfm, h * k / (h * k + c),
                         1 / (h * k + c), contacts[i].surface.mode))
            odepy.dJointAttach(odepy.dJointCreateContact(world, group, ctypes.byref(contacts[i])), b1, b2)

    callback = odepy.dNearCallback(near)
    stepper = ss.Stepper(world, registry, policy="implicit-euler", contact_group=group, solver=ss.Solver.QUICK,
                         collide=lambda s: odepy.dSpaceCollide(space, None, callback))
    gc.collect()  # the stepper keeps its C callbacks alive, whatever the caller keeps
    reports = [stepper.step(f) for f in frames(duration_s=2.0)]
    softened = sum(r.contacts.by_mapping for r in reports)
    assert sum(r.contacts.handed_to_matched + r.contacts.handed_to_implicit_euler for r in reports) == 0
    assert softened == len(seen) > 0
    for erp, cfm, want_erp, want_cfm, mode in seen:
        assert (erp, cfm) == pytest.approx((want_erp, want_cfm), rel=1e-12)
        assert mode & odepy.dContactSoftERP and mode & odepy.dContactSoftCFM
    # At rest the spring carries the weight: it sinks by m g / k.
    assert 0.1 - odepy.dBodyGetPosition(ball)[2] == pytest.approx(M * 9.81 / k, rel=1e-3)
    stepper.close()
    odepy.dJointGroupDestroy(group)
    odepy.dSpaceDestroy(space)


# ---- refusals, callbacks, failures ----------------------------------------------------------------------------

def test_null_zero_and_wrong_objects_are_refused_by_name(world):
    body, slider = oscillator(world)
    for null in (None, 0, odepy.dWorldID()):
        with pytest.raises(ss.SteadystepError, match="world = NULL: a world is required"):
            ss.Registry(null)
        with pytest.raises(ss.SteadystepError, match="world = NULL"):
            ss.Stepper(null)
    for wrong, named in ((body, "pointer to dxBody, not to dxWorld"), ("world", "a str"), (1.5, "a float"),
                         (True, "a bool"), (-1, "not an address")):
        with pytest.raises(ss.SteadystepError, match=named):
            ss.Registry(wrong)
    registry = ss.Registry(world)
    with pytest.raises(ss.SteadystepError, match="joint = NULL: a joint is required") as refused:
        registry.bind_joint(None, ss.JointParam.STOP, 1, (K, C))
    assert refused.value.code == ss.Status.OUT_OF_RANGE
    with pytest.raises(ss.SteadystepError, match="joint = .*pointer to dxBody, not to dxJoint"):
        registry.bind_joint(body, ss.JointParam.STOP, 1, (K, C))
    with pytest.raises(ss.SteadystepError) as refused:
        registry.bind_joint(slider, ss.JointParam.SUSPENSION, 1, (K, C))
    assert refused.value.code == ss.Status.UNSUPPORTED
    with pytest.raises(ss.SteadystepError, match="param = 9"):
        registry.bind_joint(slider, 9, 1, (K, C))
    with pytest.raises(ss.SteadystepError, match="space = NULL"):
        registry.adopt(1 / 60, None)
    with pytest.raises(ss.SteadystepError, match="space = .*pointer to dxBody"):
        registry.adopt(1 / 60, body)
    with pytest.raises(ss.SteadystepError, match="not found"):
        registry.unbind_joint(slider)
    assert registry.joint_binding_count == 0 and registry.tuned_step_s == 0
    with pytest.raises(ss.SteadystepError, match="max_step_s"):
        ss.Stepper(world, registry, stepping=ss.Stepping(max_step_s=-1.0), solver=ss.Solver.QUICK)
    with pytest.raises(ss.SteadystepError, match="solver = None: say which ODE step") as refused:
        ss.Stepper(world, registry, tuned_step_s=1 / 60)
    assert refused.value.code == ss.Status.UNSUPPORTED
    with pytest.raises(ss.SteadystepError, match="max_step_s = 0 s .the tuned step., but there is no tuned step"):
        ss.Stepper(world, registry, solver=ss.Solver.QUICK)
    with pytest.raises(ss.SteadystepError, match="policy"):
        ss.Stepper(world, registry, policy="fastest", solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    with pytest.raises(ss.SteadystepError, match="collide = 3: must be callable"):
        ss.Stepper(world, registry, collide=3, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    with pytest.raises(ss.SteadystepError, match="contact_group = .*pointer to dxBody"):
        ss.Stepper(world, registry, contact_group=body, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    stepper = ss.Stepper(world, registry, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    with pytest.raises(ss.SteadystepError, match="contact = NULL"):
        stepper.soften_contact(None, body, None)
    with pytest.raises(ss.SteadystepError, match="tuned step = 0 s: adopt the world first"):
        stepper.soften_contact(odepy.dContact(), body, None)
    with pytest.raises(ss.SteadystepError, match="contact = .*a dMass, not a dContact"):
        stepper.soften_contact(odepy.dMass(), body, None)
    with pytest.raises(ss.SteadystepError, match="frame_s = -1"):
        stepper.step(-1.0)
    with pytest.raises(ss.SteadystepError, match="frame_s") as refused:
        stepper.step(math.nan)
    assert refused.value.code == ss.Status.NOT_FINITE
    with pytest.raises(ss.SteadystepError, match="body = NULL"):
        stepper.destroy_body(0)
    with pytest.raises(ss.SteadystepError, match="joint = NULL"):
        stepper.destroy_joint(None)
    assert odepy.dBodyGetPosition(body)[0] == X0  # nothing moved
    stepper.destroy_joint(slider)
    stepper.destroy_body(body)
    stepper.close()


def test_an_exception_in_a_callback_is_raised_by_step_and_the_stepper_goes_on(world):
    body, slider = oscillator(world)
    calls = []

    def before(stepper):
        calls.append(stepper.current_step())
        if len(calls) == 2:
            raise KeyError("from before_step")

    stepper = ss.Stepper(world, None, before_step=before, policy="implicit-euler", solver=ss.Solver.QUICK,
                         tuned_step_s=1 / 60)
    stepper.watch_body(body)
    with pytest.raises(KeyError, match="from before_step") as raised:
        stepper.step(0.05)  # 3 substeps: the second raises, the third is taken without the callback
    assert raised.value.steadystep_report.steps == 3 and len(calls) == 2
    assert calls[0] == ss.StepInfo(ss.Mapping.IMPLICIT_EULER, 0.05 / 3, 0.05 / 3, 0.0, 0, 3)
    assert stepper.step(0.01).steps == 1 and len(calls) == 3  # not failed: the next frame is stepped as usual

    def reenter(stepper):
        stepper.step(0.01)

    again = ss.Stepper(world, None, before_step=reenter, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    with pytest.raises(ss.SteadystepError, match="called from a callback of the same stepper") as raised:
        again.step(0.01)
    assert raised.value.code == ss.Status.REENTERED
    done = ss.Stepper(world, None, step_done=lambda step_s: 1 / 0, solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    with pytest.raises(ZeroDivisionError):
        done.step(0.01)
    for made in (stepper, again, done):
        made.close()


def test_after_a_runaway_frames_are_refused_until_reset(world):
    body = box_body(world)
    stepper = ss.Stepper(world, None, stepping=ss.Stepping(max_speed=5.0), solver=ss.Solver.QUICK, tuned_step_s=1 / 60)
    stepper.watch_body(body)
    odepy.dBodySetLinearVel(body, 10.0, 0.0, 0.0)
    with pytest.raises(ss.SteadystepError) as failed:
        stepper.step(1 / 30)
    assert failed.value.code == ss.Status.SPEED_LIMIT and failed.value.report.failed_body == address(body)
    with pytest.raises(ss.SteadystepError) as refused:
        stepper.step(1 / 30)
    assert refused.value.code == ss.Status.FAILED
    odepy.dBodySetLinearVel(body, 1.0, 0.0, 0.0)  # the program's repair
    stepper.reset()
    x = odepy.dBodyGetPosition(body)[0]
    assert stepper.step(0.1).steps == 6
    assert odepy.dBodyGetPosition(body)[0] - x == pytest.approx(0.1, rel=1e-12)
    stepper.close()


def test_a_stepper_made_from_a_space_knows_what_is_spawned_and_refuses_a_nan_torque_by_name(world):
    odepy.dWorldSetGravity(world, 0.0, 0.0, 0.0)
    space = odepy.dHashSpaceCreate(None)
    first = box_body(world)
    odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), first)
    torques = []

    def before(stepper):  # a controller that divides by a span that is zero on the fourth step
        torques.append(1.0)
        if len(torques) == 4:
            odepy.dBodyAddTorque(first, math.nan, 0.0, 0.0)

    stepper = ss.Stepper(world, space=space, tuned_step_s=1 / 60, solver=ss.Solver.QUICK, before_step=before)
    assert stepper.adopted.bodies == 1 and stepper.known_body_count == 1
    assert stepper.stepping.max_step_s == 1 / 60  # 0: the tuned step
    stepper.step(0.05)
    spawned = box_body(world, mass_kg=1.0, x=3.0)  # spawned between frames, forced once a frame
    odepy.dGeomSetBody(odepy.dCreateSphere(space, 0.1), spawned)
    odepy.dBodyAddForce(spawned, 1.0, 0.0, 0.0)
    with pytest.raises(ss.SteadystepError, match=r"torque \(nan, 0, 0\) N\*m before step 1 of 3") as refused:
        stepper.step(0.05)
    assert refused.value.code == ss.Status.NOT_FINITE and refused.value.report.failed_body == address(first)
    assert stepper.adopted.bodies == 2 and stepper.known_body_count == 2
    assert odepy.dBodyGetForce(spawned)[0] == 1.0  # the refused frame left the program's forces as it added them
    odepy.dBodySetTorque(first, 0.0, 0.0, 0.0)  # the repair; the refused frame is not played again
    odepy.dBodySetForce(spawned, 0.0, 0.0, 0.0)
    stepper.reset()
    for _ in range(10):
        odepy.dBodyAddForce(spawned, 1.0, 0.0, 0.0)
        stepper.step(0.05)
    assert odepy.dBodyGetLinearVel(spawned)[0] == pytest.approx(0.5, abs=1e-9)  # F·t / m, every frame whole
    stepper.close()
    odepy.dSpaceDestroy(space)
