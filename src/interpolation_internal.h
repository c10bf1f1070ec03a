/* The stepper's history of poses under SS_CUT_FIXED (steadystep/interpolation.h): for every known body the pose
 * before the frame's last step and after it. stepper.c calls these around a fixed frame; each call is one pass over
 * the known bodies at most, and only the frames that take a step read ODE twice (the cost the benchmark measures). */
#ifndef STEADYSTEP_INTERPOLATION_INTERNAL_H
#define STEADYSTEP_INTERPOLATION_INTERNAL_H

#include <ode/ode.h>

#include "steadystep/status.h"
#include "steadystep/stepper.h"

typedef struct ssPoseHistory ssPoseHistory;

/** Before a fixed frame: follows the known bodies (bodies: sorted by address, count of them; *history made on the
 *  first call), a body new to it starting from its pose now. Errors: SS_ERROR_OUT_OF_MEMORY, *history kept. */
ssStatus ssPoseHistoryBeginFrame(ssPoseHistory** history, const dBodyID* bodies, int count);

/** Just before the frame's last physics step: every body's pose now is its previous state. */
void ssPoseHistoryBeforeLastStep(ssPoseHistory* history);

/** After the frame: steps > 0, every body's pose now is its current state; steps = 0, a body whose pose is not its
 *  current state (the program set it between frames) starts again from there. interpolation: the frame's factor. */
void ssPoseHistoryEndFrame(ssPoseHistory* history, int steps, double interpolation);

/** A body the stepper destroys (ssStepper_DestroyBody, from a callback too): never read again. */
void ssPoseHistoryForgetBody(ssPoseHistory* history, dBodyID body);

/** Every body starts again from its pose at the next frame (ssStepper_Reset, ssStepper_SetStepping). */
void ssPoseHistoryForget(ssPoseHistory* history);

/** The blended pose of body (interpolation.h); SS_ERROR_NOT_FOUND when the history does not hold it. */
ssStatus ssPoseHistoryPose(const ssPoseHistory* history, dBodyID body, double position[3], double quaternion[4]);

void ssPoseHistoryDestroy(ssPoseHistory* history);

/** stepper.c: where the stepper keeps its history (NULL until its first fixed frame or SetInterpolation). */
ssPoseHistory** ssStepperPoseSlot(ssStepper* stepper);

/** Slerp of unit quaternions (w, x, y, z) on the shortest arc at a in [0, 1]; out may alias neither input. */
void ssSlerp(const double from[4], const double to[4], double a, double out[4]);

#endif
