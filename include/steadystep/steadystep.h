/* steadystep: frame-rate independent constraint softness for the Open Dynamics Engine. The whole API of the library
 * that programs link (the lab's profiles and scenes are apart, under lab/, and not installed). */
#ifndef STEADYSTEP_H
#define STEADYSTEP_H

#include "steadystep/status.h"
#include "steadystep/limits.h"
#include "steadystep/spring.h"
#include "steadystep/stepping.h"
#include "steadystep/registry.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"
#include "steadystep/interpolation.h"

#endif
