/* steadystep: reference scenes built with ODE, and runs of a scene under a profile and a policy.
 *
 * A scene is data plus a builder: it makes its world, binds its soft parts in a registry, drives a stepper, and
 * reports a few followed quantities after every physics step. This header uses no ODE types, so that any language
 * can drive scenes (the Python package reads it with cffi).
 *
 * Scenes (quantities in parentheses):
 *   oscillator  one body on a slider whose stop (lo = hi = 0) is the spring; no gravity unless params.gravity;
 *               the article's case (x m, v m/s, erp, cfm of the stop for that step)
 *   buggy       a four-wheeled car with hinge-2 wheels on spring suspension, driving over bumps
 *               (chassis height m, chassis pitch rad)
 *   drop        boxes dropped onto the ground with soft contacts from the spring (penetration m, height m)
 *   chain       a chain of links on hinge joints with soft limits (+-0.4 rad), pinned at one end and released
 *               horizontal under gravity (end x m, end z m)
 *   pile        many boxes in a heap for timing (mean height m)
 * and three written as ODE programs are (after ODE's demos), their ERP/CFM, damping and auto-disable tuned at
 * 1/60 s and adopted with ssRegistry_Adopt, contacts softened with ssStepper_SoftenContact; params.spring is what
 * their main tuned softness stands for at 1/60 s:
 *   stack       a tower of six boxes 200 times apart in mass (20 kg at the bottom, 0.1 kg near the top), heavier
 *               ones on lighter ones; world ERP 0.2 and contacts' soft CFM 1e-3 (spring: per contact point);
 *               damping and auto-disable (20 steps) counted in steps, 40 QuickStep iterations; its top box pushed
 *               sideways for 3 s, then it comes to rest and sleeps (top x m, top z m, kinetic energy J);
 *               params.mass is the lightest box's mass, body_count the boxes from the bottom (at most 6)
 *   wall        a wall of 69 bricks (0.4 m, params.mass each) in six courses, hit at 12 m/s by a ball ten times a
 *               brick's mass and knocked over: hundreds of contacts a step; contacts' soft ERP 0.5 and soft CFM
 *               0.01, auto-disable after 10 steps (wall mean displacement m, ball x m, ball z m). Not demo_crash's
 *               own soft ERP 0.8: with it the matched and exact mappings throw the standing wall apart before the
 *               ball arrives (exact doubles its energy by 0.17 s), while implicit Euler holds it (issue 15)
 *   piston      a ram (params.mass) on a slider, driven by its motor (0.8 m/s, 40 N) into its stops at +-0.25 m and
 *               reversed every second, with an arm on a hinge swinging into its stops at +-0.35 rad; stops soft
 *               by their StopERP/StopCFM (slider: 0.3, 1e-3, the spring; arm: 0.3, 0.1) (ram x m, ram v m/s,
 *               arm angle rad)
 *
 * Sanity bounds. Every scene declares bounds that a physically correct run never reaches, checked after every
 * physics step (in the lab, not the core library: they are facts about these scenes, not about ODE). Leaving one
 * means the run is finite but wrong: a torn joint, a box through the floor, a spring that made energy. Each scene's
 * file gives the reasons for its numbers; tests/c/test_bounds.cpp measures how close correct runs come (at most
 * 0.66 of a bound: pile's boxes landing at 30 fps; the wall starts at 0.5 of its energy bound) and shows wrong ones
 * broken:
 *   oscillator  energy above its rest state, (1/2) m v^2 + (1/2) k (x - x_rest)^2 with x_rest = -m g / k, at most
 *               2 E0 + rounding (E0 its value at release): gravity is conservative and nothing drives the body, so
 *               energy can only fall
 *   buggy       the chassis' lowest corner at most 0.05 m (half its half height) below the ground; each wheel's
 *               hinge-2 anchors at most 0.045 m (a quarter of the wheel radius) apart across the suspension axis,
 *               and at most 0.28 m apart along it (the wheel up through the chassis' roof)
 *   drop        each box's lowest corner at most 0.05 m (half its half side) below the floor
 *   pile        each box's lowest corner at most 0.1 m (its half side) below the floor: its boxes fall from higher,
 *               and a 1/60 s step finds their first contact deeper
 *   chain       each hinge's two anchors (one on each link, or the world's) at most 0.05 m (a fifth of a link)
 *               apart
 *   stack       neighbours overlapping by at most 0.07 m (a quarter of the smallest side); each box's centre at
 *               most a third of its side across from the one below (slid off or fallen)
 *   wall        energy above the resting state at most twice its value at the start (nothing drives the wall;
 *               checked with gravity > 0, which gives a resting state);
 *               no brick's centre below the floor
 *   piston      the ram at most 0.06 m beyond a stop (a 1/15 s step at the motor's speed passes it by 5.3 cm), the
 *               arm at most 0.25 rad beyond its stops; the ram at most 0.01 m off its axis and the hinge's
 *               anchors at most 0.01 m apart
 * A run that leaves a bound ends there as broken (ssRun_Outcome), its message naming the time, the bound, the body
 * or joint and the value.
 */
#ifndef STEADYSTEP_SCENE_H
#define STEADYSTEP_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "steadystep/lab/export.h"
#include "steadystep/limits.h"
#include "steadystep/spring.h"
#include "steadystep/status.h"
#include "steadystep/stepping.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SS_MAX_QUANTITIES 4

/** A run (ssRun_Execute) takes at most this many frames and this many physics steps: 10^7 each. A run records 2 + 4
 *  doubles per step, so the largest run holds about 480 MB. A run expected to need more is refused before it
 *  starts; one that reaches the bound (a random profile's unlucky draw) stops with SS_ERROR_OUT_OF_RANGE. */
#define SS_MAX_RUN_FRAMES 10000000
#define SS_MAX_RUN_STEPS 10000000

/** The longest simulated duration (s) of a run: 10^6 s (about 11.6 days). */
#define SS_MAX_RUN_DURATION_S 1e6

/** The largest |x0| (m) and |gravity| (m/s²) a scene takes: scenes are a few metres across; far beyond these, ODE's
 *  products of error, stiffness and step overflow inside a step (limits.h). */
#define SS_SCENE_MAX_X0_M 1e3
#define SS_SCENE_MAX_GRAVITY_M_PER_S2 1e4

/** A scene's parameters. Start from ssDefaultSceneParams(name): each scene has its own defaults. */
typedef struct ssSceneParams {
  ssSpring spring;     /* the scene's soft constraint: slider stop, suspension, contact or joint limit */
  double mass;         /* kg, in [SS_MIN_MASS_KG, SS_MAX_MASS_KG]: the oscillator's body, a buggy's chassis, each
                        * dropped box, each chain link, the stack's lightest box, each brick, the ram */
  double x0;           /* m, |x0| <= SS_SCENE_MAX_X0_M: the oscillator's initial extension (released at rest);
                        * unused elsewhere */
  double gravity;      /* m/s² along the scene's "down", |gravity| <= SS_SCENE_MAX_GRAVITY_M_PER_S2: oscillator 0
                        * by default (along the slider), others 9.81 */
  int body_count;      /* pile, drop, stack: boxes; chain: links; wall: bricks; 0 = the scene's default */
} ssSceneParams;

/** What a scene follows. */
typedef struct ssSceneInfo {
  const char* name;
  const char* description;
  int quantity_count;
  const char* quantity_names[SS_MAX_QUANTITIES];
  const char* quantity_units[SS_MAX_QUANTITIES];
} ssSceneInfo;

/** The number of scenes, and each scene's description (NULL past the end). */
SS_LAB_API int ssSceneCount(void);
SS_LAB_API const ssSceneInfo* ssSceneInfoAt(int index);
/** The scene called name, or NULL (also for name = NULL). */
SS_LAB_API const ssSceneInfo* ssSceneFind(const char* name);

/** A quantity's column name in the lab's tables (the CSV of `steadystep run` and examples/oscillator.c, the JSON
 *  columns): name, then '_' and unit, spelled with letters, digits and '_' only: '/' as "_per_", spaces, '*' and '-'
 *  as '_', parentheses and '^' dropped; a dimensionless quantity (unit "") has no suffix. E.g. ("t", "s") "t_s",
 *  ("v", "m/s") "v_m_per_s", ("cfm", "m/(N*s)") "cfm_m_per_N_s", ("chassis pitch", "rad") "chassis_pitch_rad",
 *  ("erp", "") "erp". Writes at most size bytes into out, always NUL-terminated when size > 0, and returns the
 *  length of the whole name (as snprintf: a return >= size means out was too small). Errors: -1, with
 *  "name = NULL: ..." (or unit, or out with size > 0) for ssLastError(). */
SS_LAB_API int ssColumnName(const char* name, const char* unit, char* out, size_t size);

/** The default parameters of a scene. Errors (*out untouched): SS_ERROR_NOT_FOUND for an unknown scene (named),
 *  SS_ERROR_OUT_OF_RANGE for name = NULL or out = NULL. */
SS_LAB_API ssStatus ssDefaultSceneParams(const char* name, ssSceneParams* out);

/** The naive policy's reference step in the lab (s): the softness of the scenes that bind their springs by hand
 *  frozen as if tuned at 30 fps. The scenes written as ODE programs (stack, wall, piston) are adopted at their own
 *  tuned step, and a frozen policy freezes them there: naive is their own stepping. */
#define SS_LAB_NAIVE_REFERENCE_STEP_S (1.0 / 30.0)

/** The lab's longest substep and fixed step (s): 1/60. The lab's scenes bind their springs by hand and have no
 *  tuned step for stepping.max_step_s = 0 to stand for. */
#define SS_LAB_STEP_S (1.0 / 60.0)

/** The stepping of a policy in the lab: ssDefaultStepping() with the policy's cut and mapping (stepping.h), naive
 *  frozen at SS_LAB_NAIVE_REFERENCE_STEP_S, solver SS_SOLVER_QUICK, max_step_s = fixed_step_s = SS_LAB_STEP_S.
 *  Errors: those of ssSteppingForPolicy. */
SS_LAB_API ssStatus ssLabStepping(const char* policy, ssStepping* out);

/** The stepping of a reference run: implicit Euler with substeps of at most step_s (s, in the step range; e.g.
 *  1/1000), fixed_step_s also step_s, solver SS_SOLVER_QUICK, the other fields as ssDefaultStepping. Run it under the
 *  profile "fixed:N" with N = 1/step_s (e.g. "fixed:1000") so that every frame is one step. step_s is not checked
 *  here: ssScene_Create refuses a bad one. */
SS_LAB_API ssStepping ssReferenceStepping(double step_s);

typedef struct ssScene ssScene;

/** Builds a scene. Errors (*out untouched): SS_ERROR_NOT_FOUND (unknown scene), those of ssValidateSpring,
 *  SS_ERROR_OUT_OF_RANGE (name, params, stepping or out NULL; mass outside [SS_MIN_MASS_KG, SS_MAX_MASS_KG], x0 or
 *  gravity beyond their bounds above, body_count < 0 or above the scene's maximum, a step length outside
 *  [SS_MIN_STEP_S, SS_MAX_STEP_S], another stepping field out of range), SS_ERROR_NOT_FINITE, SS_ERROR_UNSUPPORTED
 *  (unknown policy or solver), SS_ERROR_OUT_OF_MEMORY. */
SS_LAB_API ssStatus ssScene_Create(const char* name, const ssSceneParams* params, const ssStepping* stepping,
                                   ssScene** out);

/** Destroys the scene and its ODE world. NULL is a no-op. */
SS_LAB_API void ssScene_Destroy(ssScene* scene);

/** Advances one frame of frame_s seconds through the scene's stepper. steps (may be NULL) receives the physics
 *  steps taken. Every body is watched, with a speed limit of 100 m/s (no scene moves anything near that fast).
 *  Each scene keeps its own state of ODE's process-wide random generator (dWorldQuickStep shuffles its rows with
 *  it), so a run does not depend on what else ran in the process; step scenes from one thread at a time.
 *  Errors: those of ssStepper_Step (SS_ERROR_BLOWUP, SS_ERROR_SPEED_LIMIT when the scene explodes),
 *  SS_ERROR_OUT_OF_RANGE for scene = NULL. */
SS_LAB_API ssStatus ssScene_Frame(ssScene* scene, double frame_s, int* steps);

/** The followed quantities now, quantity_count of them, into out. scene or out NULL: writes nothing and records
 *  "scene = NULL: ..." (or out) for ssLastError(). */
SS_LAB_API void ssScene_Sample(const ssScene* scene, double* out);

/** The scene's simulated time (s). scene = NULL: NaN, and records "scene = NULL: ..." for ssLastError(). */
SS_LAB_API double ssScene_Time(const ssScene* scene);

/** NULL while every physics step so far kept the scene within its sanity bounds (above); after the first step that
 *  left one, that violation for good: one line naming the time (s), the bound, the body or joint and the value, e.g.
 *  "t = 1.5 s: chain hinge 3: anchors 0.31 m apart, bound 0.05 m (a fifth of a 0.25 m link)". Leaving a bound is
 *  not an error: ssScene_Frame still returns SS_OK and the scene steps on; the caller decides. scene = NULL: NULL,
 *  and records "scene = NULL: ..." for ssLastError(). */
SS_LAB_API const char* ssScene_Broken(const ssScene* scene);

/** How close the scene has come to its sanity bounds: the largest value/bound ratio over every bound and every
 *  physics step so far (0 before the first step; above 1 once broken). A correct run stays well below 1; the tests
 *  measure how far. scene = NULL: NaN, and records "scene = NULL: ..." for ssLastError(). */
SS_LAB_API double ssScene_BoundUse(const ssScene* scene);
/** Who served rows or contacts (ssServedCounts, registry.h), summed over a run's steps. */
typedef struct ssSceneServedCounts {
  int64_t by_mapping;               /* served by the stepping's own mapping */
  int64_t handed_to_matched;        /* exact only: served by matched */
  int64_t handed_to_implicit_euler; /* matched/exact only: served by implicit Euler */
} ssSceneServedCounts;

/** What the scene's stepper did since the scene was built, summed over every frame (ssFrameReport, stepper.h). */
typedef struct ssSceneCounters {
  int64_t frames;                /* frames stepped with ssScene_Frame */
  int64_t steps;                 /* physics steps they took */
  ssSceneServedCounts rows;      /* row-steps: every bound row once per physics step, by who served it */
  ssSceneServedCounts contacts;  /* contacts softened through the stepper (ssStepper_SoftenContact), by who served
                                  * them: stack's and wall's; drop, pile and buggy soften theirs with
                                  * ssContactSoften, so 0 for them */
  int64_t row_writes;            /* parameter sets written into ODE */
} ssSceneCounters;

/** The scene's counters. scene = NULL: all zero, and records "scene = NULL: ..." for ssLastError(). */
SS_LAB_API ssSceneCounters ssScene_Counters(const ssScene* scene);

/** The scene's drawing: the points of a polyline in world coordinates (m, x y z each), e.g. the chain's pivot then
 *  the far end of each link. Writes at most capacity points into xyz (3 doubles each) and returns how many the
 *  scene has (call with capacity 0 to ask); 0 for a scene that has no drawing (only the chain has one), and for
 *  scene = NULL, capacity < 0 or xyz = NULL with capacity > 0, which record why for ssLastError(). */
SS_LAB_API int ssScene_Points(const ssScene* scene, double* xyz, int capacity);

/** As ssScene_Points, but each point on the pose the scene's stepper gives to draw (ssStepper_InterpolatedPose,
 *  interpolation.h): under the fixed cut blended between the last two physics states at the last frame's
 *  interpolation factor, under the other cuts ODE's pose (the same points as ssScene_Points). Same errors. */
SS_LAB_API int ssScene_InterpolatedPoints(const ssScene* scene, double* xyz, int capacity);

/** The bodies of the scene that are awake (dBodyIsEnabled): those its space's geoms reach (nested spaces
 *  included), each counted once; a body without a geom (the chain's links, the oscillator's) is not counted. Scenes with auto-disable (stack, wall) fall asleep when they come to rest; the
 *  cost benchmark compares two copies only where as many bodies are awake in both. -1 for scene = NULL, which
 *  records why for ssLastError(). */
SS_LAB_API int ssScene_AwakeBodies(const ssScene* scene);

/** Steps count frames of frames_s[i] seconds and writes the calling thread's CPU seconds they took to *cpu_s
 *  (CLOCK_THREAD_CPUTIME_ID: other work on a shared machine does not count): through the scene's stepper
 *  (plain = 0, as ssScene_Frame), or (plain = 1) as a program without the library steps, for the cost benchmark:
 *  the scene's per-step input for the frame's one step (the stack's push, the piston's motor, as the stepper gives
 *  it before each of its steps), collide, one dWorldQuickStep (or dWorldStep, per the stepping's solver) of the
 *  whole frame and empty the contacts, with every softness left as the stepper last wrote it (contacts softened as
 *  for the stepper's last step). A plain frame needs one ssScene_Frame first, so that every softness has been
 *  written.
 *  Frames through the stepper are timed without the lab's sanity bounds (ssScene_Broken, ssScene_BoundUse skip
 *  them), which a program does not pay; a plain frame checks only that the followed quantities stay finite, since
 *  ODE aborts on a step from a non-finite state.
 *  Errors: SS_ERROR_OUT_OF_RANGE (scene, frames_s or cpu_s NULL, count < 0, plain not 0 or 1, a plain frame
 *  before any ssScene_Frame, a frame outside [SS_MIN_STEP_S, SS_MAX_STEP_S] when plain); SS_ERROR_BLOWUP when a
 *  plain frame leaves a followed quantity not finite (the frames after it are not stepped); those of ssScene_Frame. */
SS_LAB_API ssStatus ssScene_TimeFrames(ssScene* scene, const double* frames_s, int count, int plain, double* cpu_s);

/** A run: a scene under a profile for duration_s, one record after every physics step. */
typedef struct ssRunDef {
  const char* scene;        /* scene name */
  ssSceneParams params;     /* from ssDefaultSceneParams */
  ssStepping stepping;      /* from ssLabStepping (or ssDefaultStepping with the solver and steps set) */
  const char* profile;      /* profile spec (profile.h) */
  uint64_t seed;            /* profile seed */
  double duration_s;        /* simulated seconds, in (0, SS_MAX_RUN_DURATION_S] (above) */
} ssRunDef;

typedef struct ssRun ssRun;

/** How a run ended. A lab-level outcome, not an ssStatus: status.h lists the library's own errors, and a broken run
 *  is no error of the library (every step succeeded) but a fact about the scene's physics. */
typedef enum ssRunOutcome {
  SS_RUN_NONE = -1,      /* only for run = NULL */
  SS_RUN_COMPLETED = 0,  /* ran for duration_s within every sanity bound */
  SS_RUN_BLEW_UP = 1,    /* ended early by SS_ERROR_BLOWUP, SS_ERROR_SPEED_LIMIT or SS_ERROR_POSITION_LIMIT
                          * (ssRun_Status says which): the state became non-finite, absurdly fast or far */
  SS_RUN_BROKEN = 2,     /* ended early at the first step outside a sanity bound (ssScene_Broken): finite but
                          * physically wrong */
} ssRunOutcome;

/** Runs def to the end, or to the first blow-up or broken step (which is recorded in the run, not an error); the
 *  records run up to and including the step that blew up or broke. Steps after it within the same frame are
 *  simulated (the stepper finishes its frame) but not recorded.
 *  A run takes at most SS_MAX_RUN_FRAMES frames and SS_MAX_RUN_STEPS physics steps (above). One expected to
 *  need more (duration_s over the profile's mean frame; steps from the policy's cut) is refused before it starts,
 *  naming duration_s; one that reaches a bound anyway (a random profile's draw) ends with SS_ERROR_OUT_OF_RANGE.
 *  Errors (*out untouched): those of ssScene_Create and ssProfile_Create; SS_ERROR_OUT_OF_RANGE for def, out,
 *  def->scene or def->profile NULL, for duration_s outside (0, SS_MAX_RUN_DURATION_S] and for the bounds above;
 *  SS_ERROR_NOT_FINITE for duration_s. */
SS_LAB_API ssStatus ssRun_Execute(const ssRunDef* def, ssRun** out);

/** Destroys the run. NULL is a no-op. */
SS_LAB_API void ssRun_Destroy(ssRun* run);

/** Records: one per physics step, time (s) after the step, the step's length (s), and each quantity (NULL for an
 *  index outside [0, quantity_count)). The arrays belong to the run.
 *  Every ssRun_ accessor given run = NULL records "run = NULL: ..." for ssLastError() and returns 0, NULL, "",
 *  NaN (ssRun_BoundUse), SS_RUN_NONE (ssRun_Outcome) or SS_ERROR_OUT_OF_RANGE (ssRun_Status). */
SS_LAB_API int ssRun_StepCount(const ssRun* run);
SS_LAB_API const double* ssRun_Times(const ssRun* run);
SS_LAB_API const double* ssRun_StepLengths(const ssRun* run);
SS_LAB_API const double* ssRun_Quantity(const ssRun* run, int index);
/** The quantities before the first step (time 0), quantity_count of them: the first row of a trajectory, kept apart
 *  from the records so that records and steps stay one to one. */
SS_LAB_API const double* ssRun_Initial(const ssRun* run);

/** Frames rendered, and the wall-clock seconds the stepping took (scene building excluded). */
SS_LAB_API int ssRun_FrameCount(const ssRun* run);
SS_LAB_API double ssRun_WallSeconds(const ssRun* run);

/** The scene's counters at the end of the run (ssScene_Counters); all zero for run = NULL. */
SS_LAB_API ssSceneCounters ssRun_Counters(const ssRun* run);

/** SS_OK (completed or broken), or the blow-up status that ended the run early. */
SS_LAB_API ssStatus ssRun_Status(const ssRun* run);
/** How the run ended (SS_RUN_NONE for run = NULL). */
SS_LAB_API ssRunOutcome ssRun_Outcome(const ssRun* run);
/** "" for a completed run; the blow-up's message, or ssScene_Broken's for a broken run. */
SS_LAB_API const char* ssRun_Message(const ssRun* run);
/** ssScene_BoundUse at the run's end: the largest value/bound ratio over every sanity bound and step. */
SS_LAB_API double ssRun_BoundUse(const ssRun* run);

#ifdef __cplusplus
}
#endif

#endif
