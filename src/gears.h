/* Internal: what the stepper does for ODE 0.16's transmission joint, which tracks each gear's phase from one step to
 * the next and aborts the process (`fabs(phase_hat - phase[i]) < M_PI`, transmission.cpp) when a gear's turn between
 * two steps is not what its spin predicted, to within pi. */
#ifndef STEADYSTEP_GEARS_H
#define STEADYSTEP_GEARS_H

#include <ode/ode.h>

/* Whether a transmission joint gears the body. */
int ssGeared(dBodyID body);

/* How far a geared body turns its gear in a step of step_s (rad): its spin, its speed over the gear's radius (a
 * gear moved sideways by its radius turns the point where the gears mesh as far as a turn of one radian would), and
 * the swing of the line between the joint's two anchors as they move apart or past each other (pi once they may
 * pass: ODE measures the phase towards the mesh, between them). The largest over its transmission joints. */
double ssGearTurn(dBodyID body, double step_s);

/* ssGearTurn at the spin and speed the body may reach by the end of the step: its accumulated torque and force (what
 * ODE applies in the step) added over step_s, the torque over the smallest principal moment of its inertia. */
double ssGearTurnInStep(dBodyID body, double step_s);

/* Makes ODE measure every transmission joint on these bodies afresh at its next step: the gears' current angles
 * become their phase 0, and the phase error between them is forgotten. For after a failure: the step that ran away
 * turned the gears by any angle (by pi exactly, often: a rotation integrated from a runaway spin), and the repair
 * that followed set their spins to something else, so ODE's prediction would no longer hold. Each gear keeps its
 * axis in its own body's frame to rounding (a rotation and its transpose), whatever the body's position. A joint
 * without two bodies, or whose body's rotation is not finite, is left alone. */
void ssGearsRebase(const dBodyID* bodies, int count);

#endif
