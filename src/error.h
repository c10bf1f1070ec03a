/* Internal: recording a failure for ssLastError(). */
#ifndef STEADYSTEP_ERROR_H
#define STEADYSTEP_ERROR_H

#include "steadystep/status.h"

/* The compiler checks a printf format against its arguments where it can (GCC, clang). */
#if defined(__GNUC__)
#define SS_PRINTF_FORMAT(format_index, first_argument) __attribute__((format(printf, format_index, first_argument)))
#else
#define SS_PRINTF_FORMAT(format_index, first_argument)
#endif

/* Records the message (printf format) for this thread and returns status, so a check reads
 * `if (bad) return ssFail(SS_ERROR_OUT_OF_RANGE, "k = %g N/m: must not be negative", k);` */
ssStatus ssFail(ssStatus status, const char* format, ...) SS_PRINTF_FORMAT(2, 3);

/* Check that value is finite and positive, finite and >= 0, or finite; the message names it (name = value unit). */
ssStatus ssCheckPositive(const char* name, const char* unit, double value);
ssStatus ssCheckNonNegative(const char* name, const char* unit, double value);
ssStatus ssCheckFinite(const char* name, const char* unit, double value);

#endif
