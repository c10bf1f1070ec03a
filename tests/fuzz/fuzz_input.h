/* Fuzz support: reading typed values from libFuzzer's bytes, and failing loudly when a promise is broken.
 *
 * Doubles come either from a table of the values that break numeric code (zeros, denormals, the extremes, NaN,
 * infinities) or from eight raw bytes, so the fuzzer reaches the edges at once and every bit pattern in time.
 * An exhausted input reads as zeros, so every input is a complete run. */
#ifndef STEADYSTEP_FUZZ_INPUT_H
#define STEADYSTEP_FUZZ_INPUT_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct FuzzInput {
  const uint8_t* data;
  size_t size;
} FuzzInput;

static inline uint8_t fuzz_byte(FuzzInput* in) {
  if (in->size == 0) return 0;
  uint8_t byte = in->data[0];
  in->data += 1;
  in->size -= 1;
  return byte;
}

static inline int fuzzEmpty(const FuzzInput* in) { return in->size == 0; }

static inline double fuzzRawDouble(FuzzInput* in) {
  uint8_t bytes[8] = {0};
  for (int i = 0; i < 8; ++i) bytes[i] = fuzz_byte(in);
  double value;
  memcpy(&value, bytes, sizeof value);
  return value;
}

/* One byte chooses: below the table's length a table value (or its negation), otherwise raw bytes. */
static inline double fuzzDouble(FuzzInput* in) {
  static const double table[] = {
      0.0,     4.9406564584124654e-324, 2.2250738585072009e-308, DBL_MIN, 1e-300, 1e-200, 1e-100, 1e-20, 1e-12,
      1e-6,    1e-3,  1.0 / 60,  1.0 / 30, 0.1,  0.5,  1.0,    2.0,    10.0,   100.0,  1e3,    1e6,    1e12,
      1e20,    1e100, 1e200,     1e300,    1e307, DBL_MAX, INFINITY, NAN,   0.9999999999999999, 1.0000000000000002,
  };
  enum { TABLE = sizeof table / sizeof table[0] };
  uint8_t choice = fuzz_byte(in);
  if (choice < 2 * TABLE) return choice % 2 ? -table[choice / 2] : table[choice / 2];
  return fuzzRawDouble(in);
}

/* A value in [lo, hi] spread evenly on a log scale, from two bytes: for physical sizes (masses) that must stay
 * within what ODE itself is asked to handle by the program. */
static inline double fuzzLogRange(FuzzInput* in, double lo, double hi) {
  unsigned raw = ((unsigned)fuzz_byte(in) << 8) | fuzz_byte(in);
  return lo * pow(hi / lo, raw / 65535.0);
}

static inline int fuzzInt(FuzzInput* in) {
  int value = 0;
  for (int i = 0; i < 4; ++i) value = (int)((unsigned)value << 8 | fuzz_byte(in));
  return value;
}

/* A broken promise: print what and where, then abort so that libFuzzer records the input as a crash. */
#define FUZZ_REQUIRE(condition, ...)                                                \
  do {                                                                              \
    if (!(condition)) {                                                             \
      fprintf(stderr, "fuzz: broken promise at %s:%d: %s\n  ", __FILE__, __LINE__, \
              #condition);                                                          \
      fprintf(stderr, __VA_ARGS__);                                                 \
      fprintf(stderr, "\n");                                                        \
      abort();                                                                      \
    }                                                                               \
  } while (0)

#endif
