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
 *                             starting with # are skipped; the last line may lack its newline); it repeats from the
 *                             start when it runs out. FILE must be a regular file (a device or a pipe is refused,
 *                             not read) of at most SS_MAX_TRACE_BYTES bytes, lines of at most
 *                             SS_MAX_TRACE_LINE_CHARS characters and no NUL byte, at most SS_MAX_TRACE_FRAMES
 *                             durations
 * Rates are in frames per second (> 0), durations in seconds (> 0). Every frame a profile hands out is finite and
 * lies in [SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S] = [1e-12 s, 3600 s] (below): a spec whose frames
 * could leave that range is refused, naming the field (so a rate is in [1/3600, 1e12] fps, a jitter's mean ± 3
 * deviations and a hitch's SECONDS inside the range, EVERY a whole number in [1, 1e9]).
 * Messages quote the spec, path and trace line with bytes outside printable ASCII written as \xNN.
 */
#ifndef STEADYSTEP_PROFILE_H
#define STEADYSTEP_PROFILE_H

#include <stdint.h>

#include "steadystep/lab/export.h"
#include "steadystep/limits.h"
#include "steadystep/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The shortest and longest frame (s) a profile hands out: 1e-12 s to SS_MAX_STEP_S (limits.h), the longest step
 *  the library takes. Frames shorter than SS_MIN_STEP_S are allowed on purpose, to exercise carrying a frame over. */
#define SS_MIN_PROFILE_FRAME_S 1e-12
#define SS_MAX_PROFILE_FRAME_S SS_MAX_STEP_S

/** Bounds on a trace file: bytes read (64 MiB), characters in one line, durations kept (10^7). */
#define SS_MAX_TRACE_BYTES 67108864
#define SS_MAX_TRACE_LINE_CHARS 4096
#define SS_MAX_TRACE_FRAMES 10000000

typedef struct ssProfile ssProfile;

/** Makes a profile from spec (above) and a seed.
 *  Errors (*out untouched): SS_ERROR_OUT_OF_RANGE for spec = NULL or out = NULL; SS_ERROR_PARSE naming the spec
 *  and the part at fault (unknown kind, missing or extra field, a number that does not parse), SS_ERROR_NOT_FINITE
 *  (a field that reads as nan or inf), SS_ERROR_OUT_OF_RANGE (a rate or duration <= 0 or giving frames outside
 *  [SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S], min above max, spread too large, EVERY not a whole number in [1, 1e9]),
 *  SS_ERROR_IO (trace file missing, unreadable, not a regular file or larger than SS_MAX_TRACE_BYTES, named),
 *  SS_ERROR_PARSE for a malformed trace line (with its number: not a number, a NUL byte, too long),
 *  SS_ERROR_OUT_OF_RANGE for a trace duration outside the frame range or more than SS_MAX_TRACE_FRAMES of them,
 *  SS_ERROR_OUT_OF_MEMORY. */
SS_LAB_API ssStatus ssProfile_Create(const char* spec, uint64_t seed, ssProfile** out);

/** Destroys the profile. NULL is a no-op. */
SS_LAB_API void ssProfile_Destroy(ssProfile* profile);

/** The next frame duration (s), finite and in [SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S].
 *  profile = NULL: returns NaN (which every consumer refuses) and records "profile = NULL: ..." for ssLastError(). */
SS_LAB_API double ssProfile_Next(ssProfile* profile);

/** Restarts the sequence from its seed. profile = NULL: does nothing and records "profile = NULL: ...". */
SS_LAB_API void ssProfile_Reset(ssProfile* profile);

/** The profile's specification as given. profile = NULL: returns "" and records "profile = NULL: ...". */
SS_LAB_API const char* ssProfile_Spec(const ssProfile* profile);

#ifdef __cplusplus
}
#endif

#endif
