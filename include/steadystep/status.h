/* steadystep: error values.
 *
 * Every fallible function returns an ssStatus. On failure nothing was changed (no output written, no ODE state
 * touched) and ssLastError() returns one line that names the offending value, e.g.
 * "step_s = -0.01 s: must be positive". The message is kept per thread until the next failure on that thread.
 *
 * One status for the core and the lab (lab/include/steadystep/lab), which reports through the same ssLastError:
 * a caller (and Python's SteadystepError.code) reads one set of values whichever part failed. SS_ERROR_IO is the
 * lab's alone (a profile's trace file); the core reads and writes no file.
 */
#ifndef STEADYSTEP_STATUS_H
#define STEADYSTEP_STATUS_H

#include "steadystep/export.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ssStatus {
  SS_OK = 0,
  SS_ERROR_NOT_FINITE = 1,        /* a NaN or an infinity where a finite number is needed */
  SS_ERROR_OUT_OF_RANGE = 2,      /* a finite number outside its valid range (h <= 0, k < 0, erp > 1, ...) */
  SS_ERROR_NO_SPRING = 3,         /* k = c = 0: no spring and no damper, so no softness exists */
  SS_ERROR_NO_FINITE_MAPPING = 4, /* the mapping does not exist for these values (matched with c = 0, ...) */
  SS_ERROR_UNSUPPORTED = 5,       /* the joint type has no such parameter or axis, or an unknown enum value */
  SS_ERROR_NOT_FOUND = 6,         /* nothing is bound to that joint or body */
  SS_ERROR_IO = 7,                /* lab only: a file could not be opened or read */
  SS_ERROR_PARSE = 8,             /* a file or a text specification is malformed */
  SS_ERROR_BLOWUP = 9,            /* a body's state became NaN or infinite */
  SS_ERROR_SPEED_LIMIT = 10,      /* a body moved faster than the configured limit */
  SS_ERROR_OUT_OF_MEMORY = 11,
  SS_ERROR_FAILED = 12,           /* an earlier frame failed: the stepper refuses frames until ssStepper_Reset */
  SS_ERROR_POSITION_LIMIT = 13,   /* a known body beyond SS_MAX_POSITION_M (limits.h), where ODE's spaces overflow */
  SS_ERROR_REENTERED = 14,        /* a stepper function that must not be called from the stepper's own callbacks was */
} ssStatus;

/** The enum's name without prefix, e.g. "out of range". Never NULL. */
SS_API const char* ssStatusName(ssStatus status);

/** The message of the last failure on this thread: one line naming the value at fault. "" when none. */
SS_API const char* ssLastError(void);

/** Records message as this thread's ssLastError() and returns status unchanged, for code built on the library
 *  that reports its own failures where the library's are read (the lab does: its status and message reach a caller,
 *  and Python's SteadystepError, as the core's do). message is copied, at most 255 bytes (longer is cut there);
 *  NULL records "". Never fails. */
SS_API ssStatus ssSetLastError(ssStatus status, const char* message);

#ifdef __cplusplus
}
#endif

#endif
