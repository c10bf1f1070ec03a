/* Fuzz target: every function of spring.h on arbitrary doubles. It checks the library's promises itself:
 *  - OK means finite outputs that are valid input again: a returned spring passes ssValidateSpring (checked here
 *    independently too), a returned softness has a finite erp and a finite cfm > 0;
 *  - an error leaves the outputs' bytes as they were (a canary pattern) and ssLastError() says something. */
#include "fuzz_input.h"
#include "steadystep/spring.h"

static const unsigned char CANARY = 0xA5;

/* The call under test with its arguments, as C, for the report of a broken promise. */
static char call[512];

static void fillCanary(void* out, size_t size) { memset(out, CANARY, size); }

static int isCanary(const void* out, size_t size) {
  const unsigned char* bytes = out;
  for (size_t i = 0; i < size; ++i)
    if (bytes[i] != CANARY) return 0;
  return 1;
}

static void requireRefusedCleanly(ssStatus status, const void* out, size_t size, const char* what) {
  FUZZ_REQUIRE(ssLastError()[0] != '\0', "%s refused (%s) without a message; %s", what, ssStatusName(status), call);
  FUZZ_REQUIRE(isCanary(out, size), "%s refused (%s: %s) but wrote its output; %s", what, ssStatusName(status),
               ssLastError(), call);
}

static void requireValidSpring(ssSpring spring, const char* what) {
  FUZZ_REQUIRE(isfinite(spring.stiffness) && isfinite(spring.damping) && spring.stiffness >= 0 &&
                   spring.damping >= 0 && (spring.stiffness > 0 || spring.damping > 0),
               "%s returned OK with k = %g, c = %g; %s", what, spring.stiffness, spring.damping, call);
  FUZZ_REQUIRE(ssValidateSpring(spring) == SS_OK, "%s returned k = %g, c = %g, which ssValidateSpring refuses: %s; %s",
               what, spring.stiffness, spring.damping, ssLastError(), call);
}

/* The bounds of what the library hands ODE (limits.h, where it exists; the same values otherwise). */
#if __has_include("steadystep/limits.h")
#include "steadystep/limits.h"
#endif
#ifndef SS_MAX_ERP
#define SS_MAX_ERP 1e9
#endif
#ifndef SS_MAX_CFM
#define SS_MAX_CFM 1e20
#endif

/* A softness returned OK: finite, cfm in (0, SS_MAX_CFM], |erp| <= SS_MAX_ERP; implicit Euler's erp in [0, 1]. */
static void requireValidSoftness(ssSoftness softness, const char* what, ssSpring spring, double mass, double h,
                                   double previous, int spring_mapping) {
  FUZZ_REQUIRE(isfinite(softness.erp) && fabs(softness.erp) <= SS_MAX_ERP && isfinite(softness.cfm) &&
                   softness.cfm > 0 && softness.cfm <= SS_MAX_CFM &&
                   (!spring_mapping || (softness.erp >= 0 && softness.erp <= 1)),
               "%s(k = %.17g, c = %.17g, mass = %.17g, h = %.17g, previous = %.17g) returned OK with erp = %g, "
               "cfm = %g",
               what, spring.stiffness, spring.damping, mass, h, previous, softness.erp, softness.cfm);
}

/* The outcome of a softness call: checked whichever way it went. */
static void checkSoftness(ssStatus status, const ssSoftness* out, const char* what, ssSpring spring, double mass,
                           double h, double previous, int spring_mapping) {
  if (status == SS_OK)
    requireValidSoftness(*out, what, spring, mass, h, previous, spring_mapping);
  else
    requireRefusedCleanly(status, out, sizeof *out, what);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in = {data, size};
  uint8_t which = fuzz_byte(&in);
  ssSpring spring = {fuzzDouble(&in), fuzzDouble(&in)};
  double a = fuzzDouble(&in), b = fuzzDouble(&in), c = fuzzDouble(&in);
  ssSoftness softness;
  ssSpring spring_out;
  snprintf(call, sizeof call, "case %d: spring = {%.17g, %.17g}, a = %.17g, b = %.17g, c = %.17g", which % 9,
           spring.stiffness, spring.damping, a, b, c);
  switch (which % 9) {
    case 0: {
      fillCanary(&softness, sizeof softness);
      checkSoftness(ssImplicitEulerSoftness(spring, a, &softness), &softness, "ssImplicitEulerSoftness", spring, 0,
                     a, 0, 1);
      break;
    }
    case 1: {
      ssSoftness given = {spring.stiffness, spring.damping};
      fillCanary(&spring_out, sizeof spring_out);
      ssStatus status = ssSpringFromSoftness(given, a, &spring_out);
      if (status == SS_OK)
        requireValidSpring(spring_out, "ssSpringFromSoftness");
      else
        requireRefusedCleanly(status, &spring_out, sizeof spring_out, "ssSpringFromSoftness");
      break;
    }
    case 2: {
      fillCanary(&spring_out, sizeof spring_out);
      ssStatus status = ssSpringFromFrequency(a, b, c, &spring_out);
      if (status == SS_OK)
        requireValidSpring(spring_out, "ssSpringFromFrequency");
      else
        requireRefusedCleanly(status, &spring_out, sizeof spring_out, "ssSpringFromFrequency");
      break;
    }
    case 3: {
      double results[2];
      fillCanary(results, sizeof results);
      ssStatus status = ssFrequencyFromSpring(spring, a, &results[0], &results[1]);
      if (status == SS_OK) {
        /* A pure damper has frequency 0 and an infinite damping ratio (documented); otherwise both finite. */
        int damper = spring.stiffness == 0;
        FUZZ_REQUIRE(isfinite(results[0]) && results[0] >= 0 && results[1] >= 0 &&
                         (damper ? results[0] == 0 && isinf(results[1]) : isfinite(results[1])),
                     "ssFrequencyFromSpring(k = %.17g, c = %.17g, mass = %.17g) returned OK with f = %g, zeta = %g",
                     spring.stiffness, spring.damping, a, results[0], results[1]);
      } else {
        requireRefusedCleanly(status, results, sizeof results, "ssFrequencyFromSpring");
      }
      break;
    }
    case 4:
      fillCanary(&softness, sizeof softness);
      checkSoftness(ssMatchedSoftness(spring, a, b, &softness), &softness, "ssMatchedSoftness", spring, a, b, 0,
                     0);
      break;
    case 5:
      fillCanary(&softness, sizeof softness);
      checkSoftness(ssExactSoftness(spring, a, b, c, &softness), &softness, "ssExactSoftness", spring, a, b, c,
                     0);
      break;
    case 6: {
      int mapping = fuzzInt(&in);
      fillCanary(&softness, sizeof softness);
      checkSoftness(ssSoftnessFor((ssMapping)mapping, spring, a, b, c, &softness), &softness, "ssSoftnessFor",
                     spring, a, b, c, mapping == SS_MAPPING_IMPLICIT_EULER);
      const char* name = ssMappingName((ssMapping)mapping);
      FUZZ_REQUIRE((mapping >= 0 && mapping <= 2) == (name != NULL), "ssMappingName(%d) = %s", mapping,
                   name ? name : "NULL");
      break;
    }
    case 7: {
      ssStatus status = ssValidateSpring(spring);
      int valid = isfinite(spring.stiffness) && isfinite(spring.damping) && spring.stiffness >= 0 &&
                  spring.damping >= 0 && (spring.stiffness > 0 || spring.damping > 0);
      FUZZ_REQUIRE((status == SS_OK) == valid, "ssValidateSpring(k = %.17g, c = %.17g) = %s", spring.stiffness,
                   spring.damping, ssStatusName(status));
      if (status != SS_OK) FUZZ_REQUIRE(ssLastError()[0] != '\0', "ssValidateSpring refused without a message");
      break;
    }
    case 8: {
      /* A round trip: a spring accepted, turned into softness at h and back, is a valid spring again. */
      fillCanary(&softness, sizeof softness);
      ssStatus status = ssImplicitEulerSoftness(spring, a, &softness);
      checkSoftness(status, &softness, "ssImplicitEulerSoftness", spring, 0, a, 0, 1);
      if (status == SS_OK && softness.erp > 0) {
        fillCanary(&spring_out, sizeof spring_out);
        status = ssSpringFromSoftness(softness, a, &spring_out);
        if (status == SS_OK)
          requireValidSpring(spring_out, "ssSpringFromSoftness(ssImplicitEulerSoftness)");
        else
          requireRefusedCleanly(status, &spring_out, sizeof spring_out, "ssSpringFromSoftness");
      }
      break;
    }
  }
  return 0;
}
