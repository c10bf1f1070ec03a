#include "lab_error.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

ssStatus ssLabFail(ssStatus status, const char* format, ...) {
  char message[256]; /* ssSetLastError keeps as much */
  va_list args;
  va_start(args, format);
  vsnprintf(message, sizeof message, format, args);
  va_end(args);
  return ssSetLastError(status, message);
}

ssStatus ssLabCheckRange(const char* name, const char* unit, double value, double low, double high) {
  if (!isfinite(value)) return ssLabFail(SS_ERROR_NOT_FINITE, "%s = %g %s: must be finite", name, value, unit);
  if (!(value >= low && value <= high))
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = %g %s: must be in [%g, %g] %s", name, value, unit, low, high, unit);
  return SS_OK;
}
