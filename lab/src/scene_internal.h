/* Internal: what a scene is made of, shared by scene.c (the table and the runner of frames), the scene files in
 * lab/src/scenes/ and run.c (which records every physics step).
 *
 * A scene is data plus a builder. scene.c owns the ODE world, its collision space, the contact group, the registry
 * and the stepper; a scene's build function only fills the world with bodies, joints and geoms, binds its soft
 * parts in the registry and returns its own state. Adding a scene is one file in lab/src/scenes/, its name in the
 * lab's source list (CMakeLists.txt) and one table line. */
#ifndef STEADYSTEP_SCENE_INTERNAL_H
#define STEADYSTEP_SCENE_INTERNAL_H

#include <ode/ode.h>

#include "steadystep/adopt.h"
#include "steadystep/registry.h"
#include "steadystep/lab/scene.h"
#include "steadystep/stepper.h"

/* What a builder gets to fill. */
typedef struct ssSceneWorld {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssRegistry* registry;
  ssStepper* stepper; /* NULL while building; set before the first step (for ssStepper_WatchBody in watch) */
} ssSceneWorld;

typedef struct ssSceneDesc {
  ssSceneInfo info;
  /* The parameters ssDefaultSceneParams hands out; body_count here is the scene's real default (never 0). */
  ssSceneParams defaults;
  /* Largest body_count the scene accepts (memory and time stay bounded); 0 = the scene ignores body_count. */
  int max_body_count;
  /* Builds into world from validated params (body_count already resolved from 0 to the default). Returns the
   * scene's state in *state. On error it frees what it made; scene.c destroys the world. */
  ssStatus (*build)(const ssSceneWorld* world, const ssSceneParams* params, void** state);
  /* Registers with the stepper the bodies the registry does not watch already (free bodies). May be NULL. */
  ssStatus (*watch)(void* state, ssStepper* stepper);
  /* The program's per-step input: forces or targets that follow the state or the time (a push, a motor's drive),
   * for a step of step_s seconds about to be taken; the scene keeps its own clock, moved on by step_s. Called before
   * every physics step (through the stepper's before_step, with ssStepper_CurrentStep's step_s) and before every
   * plain frame of ssScene_TimeFrames (with the frame's length: a program without the library gives its input
   * before each of its steps too, so that the cost benchmark compares like with like). May be NULL. */
  void (*drive)(void* state, double step_s);
  /* The stepper's collide callback: create contacts for the stepper's current step. May be NULL. */
  ssStepCallback* collide;
  /* The followed quantities after a step, info.quantity_count of them. */
  void (*sample)(const void* state, double* out);
  /* The scene's sanity bounds after a step (scene.h): returns the largest value/bound ratio over its bounds (above 1
   * means one is left; NaN values must not count, a blow-up is the stepper's to report) and, unless worst is NULL,
   * writes into it one line naming the bound, the body or joint and the value that reached it (ssBoundMessage). The
   * scene asks for the line only when a bound is left: formatting it after every step would cost more than the
   * check. May be NULL: no bounds. */
  double (*check)(const void* state, char* worst, size_t size);
  /* The scene's drawing (ssScene_Points, ssScene_InterpolatedPoints): writes at most capacity points (x y z) and
   * returns how many it has, each a point on a body placed by ssScenePointOnBody(drawn_by, ...): drawn_by NULL,
   * at ODE's pose; else at the stepper's interpolated pose. May be NULL (no drawing). */
  int (*points)(const void* state, const ssStepper* drawn_by, double* xyz, int capacity);
  /* Frees the state (ODE objects go with the world). */
  void (*destroy)(void* state);
} ssSceneDesc;

/* The world position (m) of the point at rel (m, body frame) of body: drawn_by NULL, at ODE's pose; else at the pose
 * drawn_by gives to draw (ssStepper_InterpolatedPose; ODE's pose for a body it does not know). */
void ssScenePointOnBody(const ssStepper* drawn_by, dBodyID body, const double rel[3], double out[3]);

/* The scenes, each defined in its own file under lab/src/scenes/. */
extern const ssSceneDesc ssOscillatorScene;
extern const ssSceneDesc ssBuggyScene;
extern const ssSceneDesc ssDropScene;
extern const ssSceneDesc ssChainScene;
extern const ssSceneDesc ssPileScene;
extern const ssSceneDesc ssStackScene;
extern const ssSceneDesc ssWallScene;
extern const ssSceneDesc ssPistonScene;

/* The step that the scenes written as ODE programs (stack, wall, piston) tuned their ERP/CFM, damping and
 * auto-disable for, as programs do at 60 fps; they are adopted at it (ssRegistry_Adopt). */
#define SS_PROGRAM_TUNED_STEP_S (1.0 / 60.0)

/* Called after every physics step of the scene, after its time has advanced; run.c records with it. */
typedef void ssSceneStepCallback(void* context, const ssScene* scene, double step_s);
void ssSceneSetStepObserver(ssScene* scene, ssSceneStepCallback* observer, void* context);

/* Contacts against everything in a space, softened with one spring: the near callback the contact scenes share.
 * Pairs of bodies joined by a joint do not collide. deepest_m receives the deepest contact depth of this step. */
typedef struct ssContactRecipe {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  ssSpring spring;      /* the contact's spring-damper along the normal */
  int max_contacts;     /* per pair of geoms, <= SS_MAX_PAIR_CONTACTS */
  int surface_mode;     /* extra dContact* mode bits (dContactApprox1, ...); soft ERP/CFM bits are added */
  double mu;            /* Coulomb friction coefficient (dContactApprox1: force ratio) */
  double deepest_m;     /* out: the deepest contact of the last collide call (m) */
  int contact_count;    /* out: contacts made by the last collide call */
  int refused_count;    /* out: contacts ssContactSoften refused since the scene was built (dropped, not made) */
  char refused_message[128]; /* out: the first refusal's ssLastError */
} ssContactRecipe;

#define SS_MAX_PAIR_CONTACTS 8

/* Runs dSpaceCollide on recipe->space and softens every contact for the stepper's current step. */
void ssContactCollide(ssContactRecipe* recipe, const ssStepper* stepper);

/* A sanity bound for the scenes that use a recipe: 0 while ssContactSoften refused no contact, else
 * SS_CONTACT_REFUSED_BOUND_USE (beyond the bound, finite so that the run's bound_use stays a number in JSON), naming
 * the count and the first refusal in worst: the run ends broken with the reason. */
#define SS_CONTACT_REFUSED_BOUND_USE 2.0
double ssContactRefusedCheck(const ssContactRecipe* recipe, char* worst, size_t size);

/* Contacts as an ODE program tunes them at 60 fps (the scenes written as programs): every contact gets this surface,
 * and ssStepper_SoftenContact turns its soft ERP/CFM (or the world's, where a mode bit is not set) into the softness
 * for the step about to be taken. Pairs that are both asleep or static, and pairs joined by a joint, do not collide. */
typedef struct ssTunedContacts {
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  int max_contacts;     /* per pair of geoms, <= SS_MAX_PAIR_CONTACTS */
  int surface_mode;     /* dContact* mode bits: dContactSoftCFM alone takes the world's ERP */
  double mu;            /* Coulomb friction coefficient (dContactApprox1: force ratio) */
  double soft_erp, soft_cfm; /* tuned at SS_PROGRAM_TUNED_STEP_S */
} ssTunedContacts;

void ssTunedContactsCollide(ssTunedContacts* recipe, ssStepper* stepper);

/* Boxes of one size on a ground plane whose contacts are soft with the scene's spring (drop, pile). */
typedef struct ssBoxes {
  int count;
  dBodyID* bodies;
  ssContactRecipe recipe;
} ssBoxes;

/* A check's line into worst (printf format), or nothing when worst is NULL. */
void ssBoundMessage(char* worst, size_t size, const char* format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The sanity bound of a scene of boxes on the floor (scene.h): the largest ratio of a box's lowest corner below the
 * floor to the bound, of_half_side times the box's half side; writes the deepest box into worst. */
double ssBoxesCheck(const ssBoxes* boxes, double side_m, double of_half_side, char* worst, size_t size);
/* How far the lowest corner of a box of side_m (m) is below z = 0 (m; negative when above). */
double ssBoxDepth(dBodyID box, double side_m);

/* Allocates room for params->body_count boxes, sets gravity along -z and makes the ground. scene names the scene
 * in the out-of-memory message. */
ssStatus ssBoxesCreate(const ssSceneWorld* world, const ssSceneParams* params, const char* scene, ssBoxes** out);
/* Adds one box of side_m (m) and mass_kg (kg) centred at (x, y, z). */
void ssBoxesAdd(ssBoxes* boxes, const ssSceneWorld* world, double mass_kg, double side_m, double x, double y,
                 double z);
/* The ssSceneDesc callbacks of a scene whose state is an ssBoxes. */
ssStatus ssBoxesWatch(void* state, ssStepper* stepper);
void ssBoxesCollide(void* context, ssStepper* stepper);
void ssBoxesDestroy(void* state);

/* Calls dInitODE2 once per process and allocates ODE's per-thread data once per thread; never dCloseODE. */
void ssEnsureOde(void);

#endif
