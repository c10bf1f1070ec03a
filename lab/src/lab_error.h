/* Lab-private: how the lab reports a failure. The lab is a client of the core and sees only its public headers; it
 * reports through the core's ssLastError (status.h, ssSetLastError), so that a caller reads one status and one
 * message whichever part failed. */
#ifndef STEADYSTEP_LAB_ERROR_H
#define STEADYSTEP_LAB_ERROR_H

#include "steadystep/status.h"

/* The compiler checks a printf format against its arguments where it can (GCC, clang). */
#if defined(__GNUC__)
#define SS_LAB_PRINTF_FORMAT(format_index, first_argument) __attribute__((format(printf, format_index, first_argument)))
#else
#define SS_LAB_PRINTF_FORMAT(format_index, first_argument)
#endif

/* Records the message (printf format, one line) for this thread's ssLastError() and returns status:
 * `if (bad) return ssLabFail(SS_ERROR_OUT_OF_RANGE, "duration_s = %g s: must be positive", duration_s);` */
ssStatus ssLabFail(ssStatus status, const char* format, ...) SS_LAB_PRINTF_FORMAT(2, 3);

/* SS_OK when value is finite and inside [low, high]; else SS_ERROR_NOT_FINITE or SS_ERROR_OUT_OF_RANGE with a
 * message naming it ("name = value unit: ..."). unit is printed after the value ("m", "kg"; "" for none). */
ssStatus ssLabCheckRange(const char* name, const char* unit, double value, double low, double high);

#endif
