/* steadystep: frame-rate independent constraint softness for the Open Dynamics Engine. The whole API. */
#ifndef STEADYSTEP_H
#define STEADYSTEP_H

#include "steadystep/status.h"
#include "steadystep/limits.h"
#include "steadystep/spring.h"
#include "steadystep/registry.h"
#include "steadystep/adopt.h"
#include "steadystep/stepper.h"
#include "steadystep/profile.h"
#include "steadystep/scene.h"

#endif
