#include "error.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static _Thread_local char last_error[256];

const char* ssStatusName(ssStatus status) {
  switch (status) {
    case SS_OK: return "ok";
    case SS_ERROR_NOT_FINITE: return "not finite";
    case SS_ERROR_OUT_OF_RANGE: return "out of range";
    case SS_ERROR_NO_SPRING: return "no spring";
    case SS_ERROR_NO_FINITE_MAPPING: return "no finite mapping";
    case SS_ERROR_UNSUPPORTED: return "unsupported";
    case SS_ERROR_NOT_FOUND: return "not found";
    case SS_ERROR_IO: return "i/o error";
    case SS_ERROR_PARSE: return "parse error";
    case SS_ERROR_BLOWUP: return "blow-up";
    case SS_ERROR_SPEED_LIMIT: return "speed limit";
    case SS_ERROR_OUT_OF_MEMORY: return "out of memory";
    case SS_ERROR_FAILED: return "failed earlier";
    case SS_ERROR_POSITION_LIMIT: return "position limit";
    case SS_ERROR_REENTERED: return "reentered";
  }
  return "unknown status";
}

const char* ssLastError(void) { return last_error; }

ssStatus ssSetLastError(ssStatus status, const char* message) {
  snprintf(last_error, sizeof last_error, "%s", message ? message : "");
  return status;
}

ssStatus ssFail(ssStatus status, const char* format, ...) {
  va_list args;
  va_start(args, format);
  vsnprintf(last_error, sizeof last_error, format, args);
  va_end(args);
  return status;
}

ssStatus ssCheckFinite(const char* name, const char* unit, double value) {
  if (!isfinite(value)) return ssFail(SS_ERROR_NOT_FINITE, "%s = %g %s: must be finite", name, value, unit);
  return SS_OK;
}

ssStatus ssCheckPositive(const char* name, const char* unit, double value) {
  ssStatus status = ssCheckFinite(name, unit, value);
  if (status != SS_OK) return status;
  if (value <= 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = %g %s: must be positive", name, value, unit);
  return SS_OK;
}

ssStatus ssCheckNonNegative(const char* name, const char* unit, double value) {
  ssStatus status = ssCheckFinite(name, unit, value);
  if (status != SS_OK) return status;
  if (value < 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "%s = %g %s: must not be negative", name, value, unit);
  return SS_OK;
}
