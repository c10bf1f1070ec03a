/* steadystep: frame-time profiles, the sequences of frame durations a renderer produces.
 *
 * A profile is made from a text specification; every random one is seeded and reproducible:
 *   fixed:FPS                 every frame 1/FPS s
 *   uniform:MINFPS:MAXFPS     durations uniform in [1/MAXFPS, 1/MINFPS] s (the article's 15-45 fps case)
 *   jitter:FPS:SPREAD_MS      1/FPS s plus normal noise of SPREAD_MS ms standard deviation, truncated at three
 *                             deviations; needs 3·SPREAD_MS < 1000/FPS so that no frame is shorter than zero
 *   hitch:FPS:EVERY:SECONDS   steady 1/FPS frames; every EVERY-th frame lasts SECONDS instead
 *   vsync:FPS_A:FPS_B         a game that misses vsync: runs of frames at FPS_A and FPS_B; each frame switches to
 *                             the other rate with probability 1/10
 *   trace:FILE                a recorded trace: one frame duration in seconds per line (blank lines and lines
 *                             starting with # are skipped); it repeats from the start when it runs out
 * Rates are in frames per second (> 0), durations in seconds (> 0).
 */
#ifndef STEADYSTEP_PROFILE_H
#define STEADYSTEP_PROFILE_H

#include <stdint.h>

#include "steadystep/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ssProfile ssProfile;

/** Makes a profile from spec (above) and a seed.
 *  Errors: SS_ERROR_PARSE naming the spec and the part at fault (unknown kind, missing or extra field, a number
 *  that does not parse), SS_ERROR_NOT_FINITE (a field that reads as nan or inf), SS_ERROR_OUT_OF_RANGE (a rate or
 *  duration <= 0, min above max, spread too large),
 *  SS_ERROR_IO (trace file missing or unreadable, named), SS_ERROR_PARSE for a malformed trace line (with its
 *  number), SS_ERROR_OUT_OF_MEMORY. */
ssStatus ssProfile_Create(const char* spec, uint64_t seed, ssProfile** out);

/** Destroys the profile. NULL is a no-op. */
void ssProfile_Destroy(ssProfile* profile);

/** The next frame duration (s, > 0). */
double ssProfile_Next(ssProfile* profile);

/** Restarts the sequence from its seed. */
void ssProfile_Reset(ssProfile* profile);

/** The profile's specification as given. */
const char* ssProfile_Spec(const ssProfile* profile);

#ifdef __cplusplus
}
#endif

#endif
