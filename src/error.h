/* Internal: recording a failure for ssLastError(). */
#ifndef STEADYSTEP_ERROR_H
#define STEADYSTEP_ERROR_H

#include "steadystep/status.h"

/* Records the message (printf format) for this thread and returns status, so a check reads
 * `if (bad) return ssFail(SS_ERROR_OUT_OF_RANGE, "k = %g N/m: must not be negative", k);` */
ssStatus ssFail(ssStatus status, const char* format, ...) __attribute__((format(printf, 2, 3)));

/* Check that value is finite and positive, finite and >= 0, or finite; the message names it (name = value unit). */
ssStatus ssCheckPositive(const char* name, const char* unit, double value);
ssStatus ssCheckNonNegative(const char* name, const char* unit, double value);
ssStatus ssCheckFinite(const char* name, const char* unit, double value);

#endif
