/* Frame-time profiles: the sequences of frame durations a renderer produces, parsed from a text spec.
 *
 * Parsing is strict on purpose: a profile that silently read "fixed:3O" as 3 fps would make a whole report wrong,
 * so every field must be one complete number and every refusal names the spec and the field. */
#include "steadystep/profile.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"
#include "rng.h"

typedef enum ssProfileKind {
  SS_PROFILE_FIXED,
  SS_PROFILE_UNIFORM,
  SS_PROFILE_JITTER,
  SS_PROFILE_HITCH,
  SS_PROFILE_VSYNC,
  SS_PROFILE_TRACE,
} ssProfileKind;

struct ssProfile {
  ssProfileKind kind;
  char* spec;
  uint64_t seed;
  ssRng rng;
  double a_s, b_s;    /* fixed: a; uniform: [a, b]; jitter: mean a, deviation b; hitch: a steady, b hitch;
                       * vsync: a and b the two frame lengths */
  long every;         /* hitch period in frames */
  long frame_index;   /* frames handed out since the last reset */
  int on_b;           /* vsync: currently at rate B */
  double* trace_s;
  long trace_count;
};

#define SS_MAX_FIELDS 3

typedef struct ssKindDesc {
  const char* name;
  ssProfileKind kind;
  int field_count;
  const char* fields[SS_MAX_FIELDS];
} ssKindDesc;

static const ssKindDesc kinds[] = {
    {"fixed", SS_PROFILE_FIXED, 1, {"FPS"}},
    {"uniform", SS_PROFILE_UNIFORM, 2, {"MINFPS", "MAXFPS"}},
    {"jitter", SS_PROFILE_JITTER, 2, {"FPS", "SPREAD_MS"}},
    {"hitch", SS_PROFILE_HITCH, 3, {"FPS", "EVERY", "SECONDS"}},
    {"vsync", SS_PROFILE_VSYNC, 2, {"FPS_A", "FPS_B"}},
    {"trace", SS_PROFILE_TRACE, 1, {"FILE"}},
};

/* A whole token as a number: "" , "3x", "3 " are malformed; nan and inf parse but are not finite. */
static ssStatus parse_number(const char* spec, const char* field, const char* token, double* out) {
  if (token[0] == '\0') return ssFail(SS_ERROR_PARSE, "profile \"%s\": %s is empty", spec, field);
  char* end = NULL;
  errno = 0;
  double value = strtod(token, &end);
  if (end == token || *end != '\0' || isspace((unsigned char)token[0]))
    return ssFail(SS_ERROR_PARSE, "profile \"%s\": %s = \"%s\" is not a number", spec, field, token);
  if (!isfinite(value))
    return ssFail(SS_ERROR_NOT_FINITE, "profile \"%s\": %s = %s: must be finite", spec, field, token);
  *out = value;
  return SS_OK;
}

static ssStatus check_positive(const char* spec, const char* field, double value) {
  if (value <= 0) return ssFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": %s = %g: must be positive", spec, field, value);
  return SS_OK;
}

/* Reads a trace file: one duration (s) per line, blank lines and # comments skipped. */
static ssStatus read_trace(const char* spec, const char* path, double** values_out, long* count_out) {
  FILE* file = fopen(path, "r");
  if (file == NULL)
    return ssFail(SS_ERROR_IO, "profile \"%s\": trace file \"%s\" cannot be opened: %s", spec, path, strerror(errno));
  double* values = NULL;
  long count = 0, capacity = 0, line_number = 0;
  char line[512];
  ssStatus status = SS_OK;
  while (status == SS_OK && fgets(line, sizeof line, file) != NULL) {
    ++line_number;
    size_t length = strlen(line);
    if (length == sizeof line - 1 && line[length - 1] != '\n' && !feof(file)) {
      status = ssFail(SS_ERROR_PARSE, "trace \"%s\" line %ld: longer than %zu characters", path, line_number,
                      sizeof line - 2);
      break;
    }
    while (length > 0 && isspace((unsigned char)line[length - 1])) line[--length] = '\0';
    const char* text = line;
    while (isspace((unsigned char)*text)) ++text;
    if (*text == '\0' || *text == '#') continue;
    char* end = NULL;
    double value = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(value) || value <= 0) {
      status = ssFail(SS_ERROR_PARSE, "trace \"%s\" line %ld: \"%s\" is not a positive finite duration in seconds",
                      path, line_number, text);
      break;
    }
    if (count == capacity) {
      long grown = capacity ? 2 * capacity : 64;
      double* more = realloc(values, (size_t)grown * sizeof *values);
      if (more == NULL) {
        status = ssFail(SS_ERROR_OUT_OF_MEMORY, "trace \"%s\": out of memory at line %ld", path, line_number);
        break;
      }
      values = more;
      capacity = grown;
    }
    values[count++] = value;
  }
  if (status == SS_OK && ferror(file)) status = ssFail(SS_ERROR_IO, "trace \"%s\": read error", path);
  fclose(file);
  if (status == SS_OK && count == 0)
    status = ssFail(SS_ERROR_PARSE, "trace \"%s\": no frame durations in the file", path);
  if (status != SS_OK) {
    free(values);
    return status;
  }
  *values_out = values;
  *count_out = count;
  return SS_OK;
}

/* Checks the numeric fields of a kind and fills the profile's parameters. */
static ssStatus set_parameters(ssProfile* p, const char* spec, const ssKindDesc* kind, const double* v) {
  ssStatus status = SS_OK;
  switch (kind->kind) {
    case SS_PROFILE_FIXED:
      status = check_positive(spec, "FPS", v[0]);
      p->a_s = 1.0 / v[0];
      break;
    case SS_PROFILE_UNIFORM:
      status = check_positive(spec, "MINFPS", v[0]);
      if (status == SS_OK) status = check_positive(spec, "MAXFPS", v[1]);
      if (status == SS_OK && v[0] > v[1])
        status = ssFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": MINFPS = %g is above MAXFPS = %g", spec, v[0], v[1]);
      p->a_s = 1.0 / v[1];
      p->b_s = 1.0 / v[0];
      break;
    case SS_PROFILE_JITTER:
      status = check_positive(spec, "FPS", v[0]);
      if (status == SS_OK && v[1] < 0)
        status = ssFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": SPREAD_MS = %g: must not be negative", spec, v[1]);
      if (status == SS_OK && 3.0 * v[1] >= 1000.0 / v[0])
        status = ssFail(SS_ERROR_OUT_OF_RANGE,
                        "profile \"%s\": SPREAD_MS = %g: three deviations must stay below the frame of %g ms", spec,
                        v[1], 1000.0 / v[0]);
      p->a_s = 1.0 / v[0];
      p->b_s = v[1] / 1000.0;
      break;
    case SS_PROFILE_HITCH:
      status = check_positive(spec, "FPS", v[0]);
      if (status == SS_OK && (v[1] < 1 || v[1] != floor(v[1]) || v[1] > 1e9))
        status = ssFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": EVERY = %g: must be a whole number of frames >= 1",
                        spec, v[1]);
      if (status == SS_OK) status = check_positive(spec, "SECONDS", v[2]);
      p->a_s = 1.0 / v[0];
      p->every = (long)v[1];
      p->b_s = v[2];
      break;
    case SS_PROFILE_VSYNC:
      status = check_positive(spec, "FPS_A", v[0]);
      if (status == SS_OK) status = check_positive(spec, "FPS_B", v[1]);
      p->a_s = 1.0 / v[0];
      p->b_s = 1.0 / v[1];
      break;
    case SS_PROFILE_TRACE:
      break;
  }
  return status;
}

ssStatus ssProfile_Create(const char* spec, uint64_t seed, ssProfile** out) {
  if (spec == NULL) return ssFail(SS_ERROR_PARSE, "profile spec is NULL");
  const char* colon = strchr(spec, ':');
  size_t name_length = colon ? (size_t)(colon - spec) : strlen(spec);
  const ssKindDesc* kind = NULL;
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; ++i)
    if (strlen(kinds[i].name) == name_length && strncmp(kinds[i].name, spec, name_length) == 0) kind = &kinds[i];
  if (kind == NULL)
    return ssFail(SS_ERROR_PARSE,
                  "profile \"%s\": unknown kind \"%.*s\" (fixed, uniform, jitter, hitch, vsync or trace)", spec,
                  (int)name_length, spec);
  if (colon == NULL) return ssFail(SS_ERROR_PARSE, "profile \"%s\": missing field %s", spec, kind->fields[0]);

  ssProfile profile = {.kind = kind->kind, .seed = seed};
  if (kind->kind == SS_PROFILE_TRACE) {
    /* The path is the rest of the spec: it may itself contain colons. */
    const char* path = colon + 1;
    if (*path == '\0') return ssFail(SS_ERROR_PARSE, "profile \"%s\": FILE is empty", spec);
    ssStatus status = read_trace(spec, path, &profile.trace_s, &profile.trace_count);
    if (status != SS_OK) return status;
  } else {
    double values[SS_MAX_FIELDS] = {0};
    const char* field_start = colon + 1;
    for (int i = 0; i < kind->field_count; ++i) {
      const char* field_end = strchr(field_start, ':');
      size_t length = field_end ? (size_t)(field_end - field_start) : strlen(field_start);
      char token[64];
      if (length >= sizeof token)
        return ssFail(SS_ERROR_PARSE, "profile \"%s\": %s is too long", spec, kind->fields[i]);
      memcpy(token, field_start, length);
      token[length] = '\0';
      ssStatus status = parse_number(spec, kind->fields[i], token, &values[i]);
      if (status != SS_OK) return status;
      if (i + 1 < kind->field_count && field_end == NULL)
        return ssFail(SS_ERROR_PARSE, "profile \"%s\": missing field %s", spec, kind->fields[i + 1]);
      if (i + 1 == kind->field_count && field_end != NULL)
        return ssFail(SS_ERROR_PARSE, "profile \"%s\": extra field \"%s\" after %s", spec, field_end + 1,
                      kind->fields[i]);
      field_start = field_end ? field_end + 1 : NULL;
    }
    ssStatus status = set_parameters(&profile, spec, kind, values);
    if (status != SS_OK) return status;
  }

  ssProfile* made = malloc(sizeof *made);
  char* spec_copy = malloc(strlen(spec) + 1);
  if (made == NULL || spec_copy == NULL) {
    free(made);
    free(spec_copy);
    free(profile.trace_s);
    return ssFail(SS_ERROR_OUT_OF_MEMORY, "profile \"%s\": out of memory", spec);
  }
  strcpy(spec_copy, spec);
  profile.spec = spec_copy;
  *made = profile;
  ssProfile_Reset(made);
  *out = made;
  return SS_OK;
}

void ssProfile_Destroy(ssProfile* profile) {
  if (profile == NULL) return;
  free(profile->trace_s);
  free(profile->spec);
  free(profile);
}

void ssProfile_Reset(ssProfile* profile) {
  ssRng_Seed(&profile->rng, profile->seed);
  profile->frame_index = 0;
  profile->on_b = 0;
}

const char* ssProfile_Spec(const ssProfile* profile) { return profile->spec; }

double ssProfile_Next(ssProfile* p) {
  long index = p->frame_index++;
  switch (p->kind) {
    case SS_PROFILE_FIXED:
      return p->a_s;
    case SS_PROFILE_UNIFORM:
      return p->a_s + (p->b_s - p->a_s) * ssRng_Uniform(&p->rng);
    case SS_PROFILE_JITTER: {
      /* Redrawing outside three deviations keeps the distribution symmetric, so the mean stays 1/FPS. */
      double z;
      do z = ssRng_Normal(&p->rng);
      while (fabs(z) > 3.0);
      return p->a_s + p->b_s * z;
    }
    case SS_PROFILE_HITCH:
      return (index + 1) % p->every == 0 ? p->b_s : p->a_s;
    case SS_PROFILE_VSYNC:
      /* The first frame runs at rate A; every later one switches with probability 1/10. */
      if (index > 0 && ssRng_Uniform(&p->rng) < 0.1) p->on_b = !p->on_b;
      return p->on_b ? p->b_s : p->a_s;
    case SS_PROFILE_TRACE:
      return p->trace_s[index % p->trace_count];
  }
  return p->a_s;
}
