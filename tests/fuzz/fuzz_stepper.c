/* Fuzz target: the registry and the stepper on a small world of the ODE 0.16 joint types and contacts
 * (fuzz_world.h: one to three islands an input, every joint type over the corpus).
 *
 * The input drives a sequence of operations: frames of any length (NaN, infinities, negative, denormal, huge),
 * stepping changes (lab policies, or cut, mapping, frozen step and limits fuzzed, valid or not), rebinding rows with
 * fuzzed springs and effective masses, loads, damping, auto-disable, the world's ERP/CFM, the contact softness, body
 * masses, resets, and destroying an island through the stepper (ssStepper_DestroyJoint/DestroyBody, in either
 * order, with a frame in between or not) and building it again; states and forces the program sets between frames
 * (fuzzed numbers on a body's position, velocities, force, torque); and a before_step that, at a fuzzed step of the
 * next frame, adds a fuzzed force or torque, sets a state, destroys an island, or calls ssStepper_Step,
 * SetStepping and Reset again (fuzz_callbacks.c does all of these at any step of any callback).
 *
 * Promises checked: the process never aborts; a refusal names something (ssLastError) and changes nothing (binding
 * count, body states for frame refusals); a frame reported OK leaves every body's state finite; a blow-up names the
 * body, and the stepper then refuses frames until ssStepper_Reset; so does a state or force refused at the boundary
 * (before the frame or a step), by name; re-entering is refused with SS_ERROR_REENTERED. Masses stay within
 * [1e-3, 1e3] kg: the program, not the library, hands them to ODE. */
#include "fuzz_world.h"

enum { MAX_OPS = 48 };

static void collide(void* context, ssStepper* stepper) { collideAll(context, stepper); }

/* A program's before_step doing what the plan says, once. */
static void beforeStep(void* context, ssStepper* stepper) {
  World* w = context;
  if (w->plan.what == 0 || ssStepper_CurrentStep(stepper).index != w->plan.at) return;
  int what = w->plan.what;
  w->plan.what = 0;
  int kind = pickIsland(w, (uint8_t)w->plan.kind);
  if (kind < 0) return;
  Island* island = &w->islands[kind];
  dBodyID body = island->body_count > 0 ? island->bodies[0] : 0;
  double v = w->plan.value;
  if (verbose) fprintf(stderr, "  before_step %d: plan %d, island %d, %.17g\n", w->plan.at, what, kind, v);
  switch (what) {
    case 1: if (body) dBodyAddTorque(body, v, 0, 0); break; /* a PD controller's torque, NaN included */
    case 2: if (body) dBodyAddForce(body, 0, v, 0); break;
    case 3: if (body) dBodySetAngularVel(body, 0, 0, v); break;
    case 4: if (body) teleport(w, body, v, 0, 0.5); break;
    case 5: /* destroyed and built again inside the frame: the stepper must forget the one and find the other */
      if (v > 0) destroyIslandBodies(w, kind);
      destroyIslandJoints(w, kind);
      destroyIslandBodies(w, kind);
      buildIsland(w, kind, NULL);
      break;
    default: {
      ssFrameReport inner;
      FUZZ_REQUIRE(ssStepper_Step(stepper, 1.0 / 60, &inner) == SS_ERROR_REENTERED, "Step from before_step: %s",
                   ssLastError());
      ssStepping stepping = ssStepper_Stepping(stepper);
      FUZZ_REQUIRE(ssStepper_SetStepping(stepper, &stepping) == SS_ERROR_REENTERED, "SetStepping from before_step");
      ssStepper_Reset(stepper);
      FUZZ_REQUIRE(strstr(ssLastError(), "ssStepper_Reset: called from a callback") != NULL, "Reset from before_step");
    }
  }
}

/* One frame; returns 0 when the run must end (the world blew up). A frame beyond the step budget is not stepped. */
static int frame(World* w, double frame_s, int op) {
  if (!withinBudget(w, frame_s)) return 1;
  BodyState before[STATE_CAPACITY], after[STATE_CAPACITY];
  int count = snapshot(w, before);
  int planned_destroy = w->plan.what == 5; /* bodies replaced in the frame: states are not compared */
  ssFrameReport report;
  memset(&report, 0, sizeof report); /* what a refusal leaves unwritten reads as nothing */
  if (verbose) fprintf(stderr, "op %d: stepping %.17g s\n", op, frame_s);
  ssStatus status = ssStepper_Step(w->stepper, frame_s, &report);
  if (snapshot(w, after) != count || planned_destroy) count = snapshot(w, before);
  if (verbose)
    fprintf(stderr, "op %d: %s/%s frame %.17g s: %s, %d steps, %s\n", op,
            NAME_OR_UNKNOWN(ssFrameCutName(w->stepping.cut)), NAME_OR_UNKNOWN(ssMappingName(w->stepping.mapping)),
            frame_s, ssStatusName(status), report.steps, status == SS_OK ? "" : ssLastError());
  int which = -1;
  switch (status) {
    case SS_OK:
      w->steps_left -= report.steps;
      FUZZ_REQUIRE(allFinite(after, count, &which), "op %d: frame %.17g s under %s reported OK but body %d is not "
                   "finite", op, frame_s, NAME_OR_UNKNOWN(ssMappingName(w->stepping.mapping)), which);
      FUZZ_REQUIRE(isfinite(report.simulated_s) && report.simulated_s >= 0 && report.steps >= 0,
                   "op %d: frame %.17g s: report simulated %g s in %d steps", op, frame_s, report.simulated_s,
                   report.steps);
      return 1;
    case SS_ERROR_BLOWUP:
    case SS_ERROR_SPEED_LIMIT:
    case SS_ERROR_POSITION_LIMIT:
    latched: {
      FUZZ_REQUIRE(ssLastError()[0] != '\0' && report.failed_body != 0, "op %d: %s without a message or a body", op,
                   ssStatusName(status));
      /* Latched: the next frame is refused and changes nothing. The run ends: the world is the program's to repair. */
      snapshot(w, before);
      status = ssStepper_Step(w->stepper, 1.0 / 60, &report);
      snapshot(w, after);
      FUZZ_REQUIRE(status == SS_ERROR_FAILED && memcmp(before, after, count * sizeof before[0]) == 0,
                   "op %d: the frame after a blow-up returned %s", op, ssStatusName(status));
      return 0;
    }
    default:
      if (report.failed_body != 0) goto latched; /* a force refused at the boundary, named with its body */
      FUZZ_REQUIRE(ssLastError()[0] != '\0', "op %d: frame %.17g s refused (%s) without a message", op, frame_s,
                   ssStatusName(status));
      FUZZ_REQUIRE(memcmp(before, after, count * sizeof before[0]) == 0,
                   "op %d: frame %.17g s refused (%s: %s) but the world moved", op, frame_s, ssStatusName(status),
                   ssLastError());
      return 1;
  }
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in = {data, size};
  World w;
  ssStepperDef def = ssDefaultStepperDef();
  def.collide = collide;
  def.collide_context = &w;
  def.before_step = beforeStep;
  def.before_step_context = &w;
  makeWorld(&w, &in, &def);
  for (int op = 0; op < MAX_OPS && !fuzzEmpty(&in); ++op) {
    uint8_t code = fuzz_byte(&in);
    if (verbose) fprintf(stderr, "op %d: code %d\n", op, code % 16);
    int bindings = ssRegistry_JointBindingCount(w.registry);
    switch (code % 16) {
      case 14: {
        /* A state or force the program sets between frames (a corrupt save, a teleport, a huge spin). */
        dBodyID body = pickBody(&w, fuzz_byte(&in) & 0x7F);
        uint8_t which = fuzz_byte(&in);
        double v = fuzzDouble(&in);
        if (body == 0) break;
        if (verbose) fprintf(stderr, "  set %d to %.17g\n", which % 5, v);
        switch (which % 5) {
          case 0: teleport(&w, body, v, 0, 0.5); break;
          case 1: dBodySetLinearVel(body, 0, v, 0); break;
          case 2: dBodySetAngularVel(body, v, 0, 0); break;
          case 3: dBodyAddForce(body, 0, 0, v); break;
          default: dBodyAddTorque(body, 0, v, 0); break;
        }
        break;
      }
      case 15: {
        /* What before_step does in the next frame. */
        w.plan.what = 1 + fuzz_byte(&in) % 6;
        w.plan.at = fuzz_byte(&in) % 4;
        w.plan.kind = fuzz_byte(&in);
        w.plan.value = fuzzDouble(&in);
        break;
      }
      case 0:
        if (!frame(&w, fuzzDouble(&in), op)) goto done;
        break;
      case 1: {
        int repeat = 1 + fuzz_byte(&in) % 16;
        double frame_s = fuzzDouble(&in);
        for (int i = 0; i < repeat; ++i)
          if (!frame(&w, frame_s, op)) goto done;
        break;
      }
      case 2: {
        /* A new stepping: a lab policy by index (0x80 clear) or fields fuzzed one by one. */
        uint8_t which = fuzz_byte(&in);
        ssStepping stepping = w.stepping;
        if (!(which & 0x80)) {
          const char* name = ssSteppingPolicyNameAt(which % (ssSteppingPolicyCount() + 1)); /* one past the end: NULL */
          ssStatus status = ssSteppingForPolicy(name, fuzzDouble(&in), &stepping);
          if (status != SS_OK) {
            FUZZ_REQUIRE(ssLastError()[0] != '\0' && holdsStepping(&stepping, &w.stepping),
                         "ssSteppingForPolicy(%s) refused (%s) without a message or changed the stepping",
                         name ? name : "NULL", ssStatusName(status));
            break;
          }
        } else {
          stepping.cut = (ssFrameCut)(int8_t)fuzz_byte(&in);
          stepping.mapping = (ssMapping)(int8_t)fuzz_byte(&in);
          stepping.frozen_step_s = which & 1 ? fuzzDouble(&in) : 0;
          if (which & 2) stepping.max_step_s = fuzzDouble(&in);
          if (which & 4) stepping.fixed_step_s = fuzzDouble(&in);
          if (which & 8) stepping.max_speed = fuzzDouble(&in);
          if (which & 16) stepping.max_angular_speed = fuzzDouble(&in);
        }
        ssStatus status = ssStepper_SetStepping(w.stepper, &stepping);
        ssStepping now = ssStepper_Stepping(w.stepper);
        if (status == SS_OK) {
          FUZZ_REQUIRE(holdsStepping(&now, &stepping), "SetStepping OK but the stepping differs");
          w.stepping = now;
        } else {
          FUZZ_REQUIRE(ssLastError()[0] != '\0' && holdsStepping(&now, &w.stepping),
                       "SetStepping refused (%s) without a message or changed the stepping", ssStatusName(status));
        }
        if (verbose)
          fprintf(stderr, "  SetStepping(%s/%s frozen %.17g) = %s %s\n", NAME_OR_UNKNOWN(ssFrameCutName(stepping.cut)),
                  NAME_OR_UNKNOWN(ssMappingName(stepping.mapping)), stepping.frozen_step_s, ssStatusName(status),
                  status == SS_OK ? "" : ssLastError());
        break;
      }
      case 3: {
        /* Rebind a row: a supported one (high bit clear) or any param and axis. */
        uint8_t how = fuzz_byte(&in);
        dJointID joint = pickJoint(&w, fuzz_byte(&in));
        int param = how & 0x80 ? (int8_t)fuzz_byte(&in) : how % 4;
        int axis = how & 0x80 ? (int8_t)fuzz_byte(&in) : 1 + (how >> 2) % 3;
        ssSpring spring = {fuzzDouble(&in), fuzzDouble(&in)};
        double mass = how & 0x40 ? fuzzDouble(&in) : 0;
        ssStatus status = ssRegistry_BindJoint(w.registry, joint, (ssJointParam)param, axis, spring, mass);
        if (verbose)
          fprintf(stderr, "  BindJoint(%s joint, param %d, axis %d, {%.17g, %.17g}, mass %.17g) = %s\n",
                  jointTypeName(joint), param, axis, spring.stiffness, spring.damping, mass, ssStatusName(status));
        checkRegistryCall(&w, status, bindings, "ssRegistry_BindJoint");
        break;
      }
      case 4: {
        uint8_t how = fuzz_byte(&in);
        dJointID joint = pickJoint(&w, fuzz_byte(&in));
        double load = fuzzDouble(&in);
        ssStatus status = ssRegistry_SetJointLoad(w.registry, joint, (ssJointParam)(how % 4), 1 + (how >> 2) % 3, load);
        if (verbose)
          fprintf(stderr, "  SetJointLoad(%s joint, param %d, axis %d, %.17g) = %s\n", jointTypeName(joint), how % 4,
                  1 + (how >> 2) % 3, load, ssStatusName(status));
        checkRegistryCall(&w, status, bindings, "ssRegistry_SetJointLoad");
        break;
      }
      case 5: {
        uint8_t how = fuzz_byte(&in);
        /* Destroy one of the islands (joints first, or bodies first: 0x20), with a frame in between (0x40), and
         * build it again, with fuzzed tuned values on its main joint (0x80). */
        int kind = pickIsland(&w, how & 0x1F);
        if (kind < 0) break;
        double tuned[2] = {0.2, 1e-5};
        if (how & 0x80) {
          tuned[0] = fuzzDouble(&in);
          tuned[1] = fuzzDouble(&in);
        }
        if (how & 0x20) destroyIslandBodies(&w, kind);
        else destroyIslandJoints(&w, kind);
        if ((how & 0x40) && !frame(&w, 1.0 / 60, op)) goto done;
        destroyIslandJoints(&w, kind);
        destroyIslandBodies(&w, kind);
        buildIsland(&w, kind, how & 0x80 ? tuned : NULL);
        break;
      }
      case 6: {
        dBodyID body = pickBody(&w, fuzz_byte(&in));
        double linear = fuzzDouble(&in), angular = fuzzDouble(&in);
        ssStatus status = ssRegistry_BindDamping(w.registry, body, linear, angular);
        if (verbose) fprintf(stderr, "  BindDamping(%.17g, %.17g) = %s\n", linear, angular, ssStatusName(status));
        checkRegistryCall(&w, status, bindings, "ssRegistry_BindDamping");
        break;
      }
      case 7: {
        uint8_t flags = fuzz_byte(&in);
        dBodyID body = pickBody(&w, fuzz_byte(&in));
        double idle = fuzzDouble(&in), window = fuzzDouble(&in);
        ssStatus status = ssRegistry_BindAutoDisable(w.registry, body, idle, window);
        if (verbose) fprintf(stderr, "  BindAutoDisable(%.17g, %.17g) = %s\n", idle, window, ssStatusName(status));
        checkRegistryCall(&w, status, bindings, "ssRegistry_BindAutoDisable");
        dWorldSetAutoDisableFlag(w.world, flags & 1);
        if (body != 0) dBodySetAutoDisableFlag(body, flags & 2);
        break;
      }
      case 8: {
        ssSpring spring = {fuzzDouble(&in), fuzzDouble(&in)};
        double mass = fuzzDouble(&in);
        ssStatus status = ssRegistry_BindWorld(w.registry, spring, mass);
        if (verbose)
          fprintf(stderr, "  BindWorld({%.17g, %.17g}, %.17g) = %s\n", spring.stiffness, spring.damping, mass,
                  ssStatusName(status));
        checkRegistryCall(&w, status, bindings, "ssRegistry_BindWorld");
        break;
      }
      case 9: {
        double a = fuzzDouble(&in), b = fuzzDouble(&in);
        if (w.adopt) {
          w.contact_erp = a;
          w.contact_cfm = b;
        } else {
          w.contact_spring.stiffness = a;
          w.contact_spring.damping = b;
        }
        if (verbose) fprintf(stderr, "  contact %s {%.17g, %.17g}\n", w.adopt ? "erp, cfm" : "spring", a, b);
        break;
      }
      case 10:
        ssStepper_ResetHistory(w.stepper);
        break;
      case 13:
        ssStepper_Reset(w.stepper);
        break;
      case 11: {
        dBodyID body = pickBody(&w, fuzz_byte(&in));
        if (body == 0) break;
        dMass mass;
        double kg = fuzzLogRange(&in, 1e-3, 1e3);
        if (verbose) fprintf(stderr, "  mass %.17g kg\n", kg);
        dMassSetBoxTotal(&mass, kg, 0.2, 0.2, 0.2);
        dBodySetMass(body, &mass);
        break;
      }
      case 12: {
        /* Unbind a joint and bind its supported rows again with the default spring. */
        dJointID joint = pickJoint(&w, fuzz_byte(&in));
        ssRegistry_UnbindJoint(w.registry, joint);
        bindDefaults(&w, joint);
        break;
      }
    }
  }
done:
  destroyWorld(&w);
  return 0;
}
