/* steadystep: smooth rendering of fixed steps.
 *
 * Under SS_CUT_FIXED the world advances in steps of fixed_step_s, and a frame usually ends between two of them:
 * part of its time waits in the accumulator (ssFrameReport.interpolation = accumulator / fixed_step_s, in [0, 1)).
 * Drawing ODE's state as it is would show the motion in jerks (some frames one step, some two, some none). The
 * stepper therefore keeps, for every body it knows (the registry's and the watched ones), the last two physics
 * states: the pose before the frame's last step and the pose after it, and gives the pose to draw at the frame's
 * interpolation factor a:
 *
 *   position = (1 - a) p_prev + a p_curr, rotation = slerp(q_prev, q_curr, a) on the shortest arc.
 *
 * Latency: one physics step. What is drawn lies between the last two physics states, so it shows the state of
 * one fixed step ago blended toward the latest (a = 0: exactly one step behind; a near 1: almost the latest); at
 * frame rates near the step rate that is about one frame. Input acts on the simulation at once and shows up to
 * one fixed step later. Every engine that interpolates fixed steps pays and documents the same (Godot's physics
 * interpolation, Unity's Rigidbody interpolation, Bullet's motion states); extrapolating instead would guess.
 *
 * A teleport is drawn at once: a known body whose pose the program set between frames (dBodySetPosition,
 * dBodySetQuaternion, ...) starts its history again from where the program put it, so the next frame does not
 * blend from where it was. A body the stepper comes to know, and every body after ssStepper_Reset or
 * ssStepper_SetStepping, starts likewise from its pose then.
 *
 * Under the other cuts every frame ends on a physics state: the pose given is ODE's own (a = 1), with no latency. */
#ifndef STEADYSTEP_INTERPOLATION_H
#define STEADYSTEP_INTERPOLATION_H

#include <ode/ode.h>

#include "steadystep/export.h"
#include "steadystep/status.h"
#include "steadystep/stepper.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The pose to draw body at after the last frame: position (m, world frame) and rotation as ODE's quaternion
 *  (w, x, y, z), unit length; under SS_CUT_FIXED blended between the body's last two physics states at the last
 *  frame's interpolation factor (above), else ODE's own pose. Before the first frame: ODE's pose.
 *  Call it between frames (from a callback of the stepper it gives the last frame's pose, not the step's).
 *  Errors (position and quaternion untouched): SS_ERROR_OUT_OF_RANGE (stepper, body, position or quaternion NULL),
 *  SS_ERROR_NOT_FOUND (a body the stepper does not know: neither in its registry nor watched). */
SS_API ssStatus ssStepper_InterpolatedPose(const ssStepper* stepper, dBodyID body, double position[3],
                                           double quaternion[4]);

/** on = 1 (the default): keep the poses as above under SS_CUT_FIXED; on = 0: keep nothing, and
 *  ssStepper_InterpolatedPose gives ODE's pose (a program that draws nothing: a server, a headless test). Turned on
 *  again, every body starts from its pose at the next frame. Call it between frames.
 *  Errors: SS_ERROR_OUT_OF_RANGE (stepper NULL, on neither 0 nor 1), SS_ERROR_OUT_OF_MEMORY. */
SS_API ssStatus ssStepper_SetInterpolation(ssStepper* stepper, int on);

#ifdef __cplusplus
}
#endif

#endif
