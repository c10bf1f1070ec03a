/* Internal: what run.c needs to know of a profile before it runs one. */
#ifndef STEADYSTEP_PROFILE_INTERNAL_H
#define STEADYSTEP_PROFILE_INTERNAL_H

#include "steadystep/lab/profile.h"

/* The expected frame length (s) of the profile (its mean over a long run), for bounding a run's frame count before
 * it starts. profile must not be NULL. */
double ssProfileMeanFrame(const ssProfile* profile);

#endif
