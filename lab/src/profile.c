/* Frame-time profiles: the sequences of frame durations a renderer produces, parsed from a text spec.
 *
 * Parsing is strict on purpose: a profile that silently read "fixed:3O" as 3 fps would make a whole report wrong,
 * so every field must be one complete number and every refusal names the spec and the field. Every frame handed
 * out lies in [SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S] (profile.h): the spec is refused when its frames could leave it.
 * Specs, paths and trace lines are quoted in messages with every byte outside printable ASCII written as \xNN, so
 * a message is ASCII whatever bytes came in (Python decodes it as text). */
#include "steadystep/lab/profile.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "lab_error.h"
#include "profile_internal.h"
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

/* text[0..length) as printable ASCII, other bytes as \xNN, cut with "..." to fit out (at least 8 bytes). */
static const char* escaped(const char* text, size_t length, char* out, size_t out_size) {
  size_t used = 0;
  for (size_t i = 0; i < length; ++i) {
    unsigned char byte = (unsigned char)text[i];
    int printable = byte >= 0x20 && byte < 0x7f && byte != '\\';
    size_t need = printable ? 1 : 4;
    if (used + need + 4 > out_size) {
      memcpy(out + used, "...", 4);
      return out;
    }
    if (printable)
      out[used++] = (char)byte;
    else
      used += (size_t)snprintf(out + used, 5, "\\x%02x", byte);
  }
  out[used] = '\0';
  return out;
}

/* The spec for messages, escaped; a buffer per call site keeps this free of shared state. */
#define SPEC_TEXT(spec, buffer) escaped((spec), strlen(spec), (buffer), sizeof(buffer))

/* A whole token as a number: "" , "3x", "3 " are malformed; nan and inf parse but are not finite. */
static ssStatus parseNumber(const char* raw_spec, const char* field, const char* token, double* out) {
  char spec[96], token_text[96];
  SPEC_TEXT(raw_spec, spec);
  escaped(token, strlen(token), token_text, sizeof token_text);
  if (token[0] == '\0') return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": %s is empty", spec, field);
  char* end = NULL;
  errno = 0;
  double value = strtod(token, &end);
  if (end == token || *end != '\0' || isspace((unsigned char)token[0]))
    return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": %s = \"%s\" is not a number", spec, field, token_text);
  if (!isfinite(value))
    return ssLabFail(SS_ERROR_NOT_FINITE, "profile \"%s\": %s = %s: must be finite", spec, field, token_text);
  *out = value;
  return SS_OK;
}

static ssStatus checkPositive(const char* raw_spec, const char* field, double value) {
  char spec[96];
  if (value <= 0)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": %s = %g: must be positive", SPEC_TEXT(raw_spec, spec),
                     field, value);
  return SS_OK;
}

/* A frame length (s) the field stands for: inside [SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S], or the field is refused. */
static ssStatus checkFrame(const char* raw_spec, const char* field, double field_value, double frame_s) {
  char spec[96];
  if (!(frame_s >= SS_MIN_PROFILE_FRAME_S && frame_s <= SS_MAX_PROFILE_FRAME_S))
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": %s = %g gives frames of %g s, outside [%g, %g] s",
                     SPEC_TEXT(raw_spec, spec), field, field_value, frame_s, SS_MIN_PROFILE_FRAME_S,
                     SS_MAX_PROFILE_FRAME_S);
  return SS_OK;
}

/* A rate (frames per second) whose frames 1/rate must lie in the frame range. */
static ssStatus checkRate(const char* spec, const char* field, double rate) {
  ssStatus status = checkPositive(spec, field, rate);
  if (status == SS_OK) status = checkFrame(spec, field, rate, 1.0 / rate);
  return status;
}

/* Reads at most SS_MAX_TRACE_BYTES + 1 bytes of a regular file into a NUL-terminated buffer: a device (/dev/zero),
 * a pipe or a file that keeps growing is refused, never read forever. */
static ssStatus readBounded(const char* path_text, const char* raw_path, char** text_out, size_t* length_out) {
  /* Non-blocking, so that opening a FIFO without a writer returns at once instead of waiting for one. */
  int fd = open(raw_path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return ssLabFail(SS_ERROR_IO, "trace \"%s\" cannot be opened: %s", path_text, strerror(errno));
  struct stat info;
  if (fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    close(fd);
    return ssLabFail(SS_ERROR_IO, "trace \"%s\": not a regular file (devices and pipes are not read)", path_text);
  }
  if (info.st_size > SS_MAX_TRACE_BYTES) {
    close(fd);
    return ssLabFail(SS_ERROR_IO, "trace \"%s\": %lld bytes, larger than %d", path_text, (long long)info.st_size,
                     SS_MAX_TRACE_BYTES);
  }
  FILE* file = fdopen(fd, "rb");
  if (file == NULL) {
    close(fd);
    return ssLabFail(SS_ERROR_IO, "trace \"%s\" cannot be read: %s", path_text, strerror(errno));
  }
  /* Start from the size the file reports and grow to the bound: /proc-like files report 0, growing files more. */
  size_t capacity = (size_t)(info.st_size < SS_MAX_TRACE_BYTES ? info.st_size : SS_MAX_TRACE_BYTES) + 2;
  char* text = malloc(capacity);
  size_t length = 0;
  ssStatus status = SS_OK;
  while (text != NULL) {
    length += fread(text + length, 1, capacity - 1 - length, file);
    if (length < capacity - 1 || length > SS_MAX_TRACE_BYTES) break; /* the end, or past the bound */
    size_t grown = 2 * capacity > (size_t)SS_MAX_TRACE_BYTES + 2 ? (size_t)SS_MAX_TRACE_BYTES + 2 : 2 * capacity;
    char* more = realloc(text, grown);
    if (more == NULL) free(text);
    text = more;
    capacity = grown;
  }
  int failed = ferror(file);
  fclose(file);
  if (text == NULL) return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "trace \"%s\": out of memory", path_text);
  if (failed) status = ssLabFail(SS_ERROR_IO, "trace \"%s\": read error", path_text);
  else if (length > SS_MAX_TRACE_BYTES)
    status = ssLabFail(SS_ERROR_IO, "trace \"%s\": larger than %d bytes", path_text, SS_MAX_TRACE_BYTES);
  if (status != SS_OK) {
    free(text);
    return status;
  }
  text[length] = '\0';
  *text_out = text;
  *length_out = length;
  return SS_OK;
}

/* One line's duration, or SS_OK with *has_value = 0 for a blank or comment line. line is NUL-terminated. */
static ssStatus parseTraceLine(const char* path_text, long number, char* line, size_t length, double* value,
                                 int* has_value) {
  char line_text[96];
  *has_value = 0;
  if (memchr(line, '\0', length) != NULL)
    return ssLabFail(SS_ERROR_PARSE, "trace \"%s\" line %ld: contains a NUL byte", path_text, number);
  if (length > SS_MAX_TRACE_LINE_CHARS)
    return ssLabFail(SS_ERROR_PARSE, "trace \"%s\" line %ld: longer than %d characters", path_text, number,
                     SS_MAX_TRACE_LINE_CHARS);
  while (length > 0 && isspace((unsigned char)line[length - 1])) line[--length] = '\0';
  const char* text = line;
  while (isspace((unsigned char)*text)) ++text;
  if (*text == '\0' || *text == '#') return SS_OK;
  char* end = NULL;
  double parsed = strtod(text, &end);
  if (end == text || *end != '\0' || !isfinite(parsed) || parsed <= 0)
    return ssLabFail(SS_ERROR_PARSE, "trace \"%s\" line %ld: \"%s\" is not a positive finite duration in seconds",
                     path_text, number, escaped(text, strlen(text), line_text, sizeof line_text));
  if (!(parsed >= SS_MIN_PROFILE_FRAME_S && parsed <= SS_MAX_PROFILE_FRAME_S))
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "trace \"%s\" line %ld: %g s is outside [%g, %g] s", path_text, number,
                     parsed, SS_MIN_PROFILE_FRAME_S, SS_MAX_PROFILE_FRAME_S);
  *value = parsed;
  *has_value = 1;
  return SS_OK;
}

/* Reads a trace file: one duration (s) per line, blank lines and # comments skipped; the last line may lack its
 * newline. Bounded in bytes, line length and frames (profile.h). */
static ssStatus readTrace(const char* raw_path, double** values_out, long* count_out) {
  char path_text[128];
  escaped(raw_path, strlen(raw_path), path_text, sizeof path_text);
  char* text = NULL;
  size_t length = 0;
  ssStatus status = readBounded(path_text, raw_path, &text, &length);
  if (status != SS_OK) return status;
  double* values = NULL;
  long count = 0, capacity = 0, line_number = 0;
  for (size_t start = 0; status == SS_OK && start < length;) {
    char* newline = memchr(text + start, '\n', length - start);
    size_t stop = newline != NULL ? (size_t)(newline - text) : length;
    text[stop] = '\0';
    ++line_number;
    double value = 0;
    int has_value = 0;
    status = parseTraceLine(path_text, line_number, text + start, stop - start, &value, &has_value);
    start = stop + 1;
    if (status != SS_OK || !has_value) continue;
    if (count == SS_MAX_TRACE_FRAMES) {
      status = ssLabFail(SS_ERROR_OUT_OF_RANGE, "trace \"%s\": more than %d frame durations", path_text,
                         SS_MAX_TRACE_FRAMES);
      break;
    }
    if (count == capacity) {
      long grown = capacity ? 2 * capacity : 64;
      double* more = realloc(values, (size_t)grown * sizeof *values);
      if (more == NULL) {
        status = ssLabFail(SS_ERROR_OUT_OF_MEMORY, "trace \"%s\": out of memory at line %ld", path_text, line_number);
        break;
      }
      values = more;
      capacity = grown;
    }
    values[count++] = value;
  }
  free(text);
  if (status == SS_OK && count == 0)
    status = ssLabFail(SS_ERROR_PARSE, "trace \"%s\": no frame durations in the file", path_text);
  if (status != SS_OK) {
    free(values);
    return status;
  }
  *values_out = values;
  *count_out = count;
  return SS_OK;
}

/* Checks the numeric fields of a kind and fills the profile's parameters; nothing is converted before its check. */
static ssStatus setParameters(ssProfile* p, const char* raw_spec, const ssKindDesc* kind, const double* v) {
  char spec[96];
  SPEC_TEXT(raw_spec, spec);
  ssStatus status = SS_OK;
  switch (kind->kind) {
    case SS_PROFILE_FIXED:
      status = checkRate(raw_spec, "FPS", v[0]);
      p->a_s = 1.0 / v[0];
      break;
    case SS_PROFILE_UNIFORM:
      status = checkRate(raw_spec, "MINFPS", v[0]);
      if (status == SS_OK) status = checkRate(raw_spec, "MAXFPS", v[1]);
      if (status == SS_OK && v[0] > v[1])
        status = ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": MINFPS = %g is above MAXFPS = %g", spec, v[0], v[1]);
      p->a_s = 1.0 / v[1];
      p->b_s = 1.0 / v[0];
      break;
    case SS_PROFILE_JITTER:
      status = checkRate(raw_spec, "FPS", v[0]);
      if (status == SS_OK && v[1] < 0)
        status = ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile \"%s\": SPREAD_MS = %g: must not be negative", spec, v[1]);
      if (status == SS_OK && 3.0 * v[1] >= 1000.0 / v[0])
        status = ssLabFail(SS_ERROR_OUT_OF_RANGE,
                           "profile \"%s\": SPREAD_MS = %g: three deviations must stay below the frame of %g ms", spec,
                           v[1], 1000.0 / v[0]);
      p->a_s = 1.0 / v[0];
      p->b_s = v[1] / 1000.0;
      if (status == SS_OK) status = checkFrame(raw_spec, "SPREAD_MS", v[1], p->a_s - 3.0 * p->b_s);
      if (status == SS_OK) status = checkFrame(raw_spec, "SPREAD_MS", v[1], p->a_s + 3.0 * p->b_s);
      break;
    case SS_PROFILE_HITCH:
      status = checkRate(raw_spec, "FPS", v[0]);
      if (status == SS_OK && !(v[1] >= 1 && v[1] <= 1e9 && v[1] == floor(v[1])))
        status = ssLabFail(SS_ERROR_OUT_OF_RANGE,
                           "profile \"%s\": EVERY = %g: must be a whole number of frames in [1, 1e9]", spec, v[1]);
      if (status == SS_OK) status = checkPositive(raw_spec, "SECONDS", v[2]);
      if (status == SS_OK) status = checkFrame(raw_spec, "SECONDS", v[2], v[2]);
      if (status != SS_OK) break;
      p->a_s = 1.0 / v[0];
      p->every = (long)v[1];
      p->b_s = v[2];
      break;
    case SS_PROFILE_VSYNC:
      status = checkRate(raw_spec, "FPS_A", v[0]);
      if (status == SS_OK) status = checkRate(raw_spec, "FPS_B", v[1]);
      p->a_s = 1.0 / v[0];
      p->b_s = 1.0 / v[1];
      break;
    case SS_PROFILE_TRACE:
      break;
  }
  return status;
}

ssStatus ssProfile_Create(const char* spec, uint64_t seed, ssProfile** out) {
  if (spec == NULL || out == NULL)
    return ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssProfile_Create needs a spec and somewhere to write",
                     spec == NULL ? "spec" : "out");
  char spec_text[96];
  SPEC_TEXT(spec, spec_text);
  const char* colon = strchr(spec, ':');
  size_t name_length = colon ? (size_t)(colon - spec) : strlen(spec);
  const ssKindDesc* kind = NULL;
  for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; ++i)
    if (strlen(kinds[i].name) == name_length && strncmp(kinds[i].name, spec, name_length) == 0) kind = &kinds[i];
  if (kind == NULL)
    return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": unknown kind (fixed, uniform, jitter, hitch, vsync or trace)",
                     spec_text);
  if (colon == NULL) return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": missing field %s", spec_text, kind->fields[0]);

  ssProfile profile = {.kind = kind->kind, .seed = seed};
  if (kind->kind == SS_PROFILE_TRACE) {
    /* The path is the rest of the spec: it may itself contain colons. */
    const char* path = colon + 1;
    if (*path == '\0') return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": FILE is empty", spec_text);
    ssStatus status = readTrace(path, &profile.trace_s, &profile.trace_count);
    if (status != SS_OK) return status;
  } else {
    double values[SS_MAX_FIELDS] = {0};
    const char* field_start = colon + 1;
    for (int i = 0; i < kind->field_count; ++i) {
      const char* field_end = strchr(field_start, ':');
      size_t length = field_end ? (size_t)(field_end - field_start) : strlen(field_start);
      char token[64];
      if (length >= sizeof token)
        return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": %s is too long", spec_text, kind->fields[i]);
      memcpy(token, field_start, length);
      token[length] = '\0';
      ssStatus status = parseNumber(spec, kind->fields[i], token, &values[i]);
      if (status != SS_OK) return status;
      if (i + 1 < kind->field_count && field_end == NULL)
        return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": missing field %s", spec_text, kind->fields[i + 1]);
      if (i + 1 == kind->field_count && field_end != NULL)
        return ssLabFail(SS_ERROR_PARSE, "profile \"%s\": extra field after %s", spec_text, kind->fields[i]);
      field_start = field_end ? field_end + 1 : NULL;
    }
    ssStatus status = setParameters(&profile, spec, kind, values);
    if (status != SS_OK) return status;
  }

  ssProfile* made = malloc(sizeof *made);
  char* spec_copy = malloc(strlen(spec) + 1);
  if (made == NULL || spec_copy == NULL) {
    free(made);
    free(spec_copy);
    free(profile.trace_s);
    return ssLabFail(SS_ERROR_OUT_OF_MEMORY, "profile \"%s\": out of memory", spec_text);
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
  if (profile == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile = NULL: no profile to reset");
    return;
  }
  ssRngSeed(&profile->rng, profile->seed);
  profile->frame_index = 0;
  profile->on_b = 0;
}

const char* ssProfile_Spec(const ssProfile* profile) {
  if (profile == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile = NULL: no profile to describe");
    return "";
  }
  return profile->spec;
}

/* Rounding in a + (b - a)·u and a + b·z could step a hair outside [a, b]; the range is a promise, so clamp. */
static double clamp(double value, double low, double high) { return value < low ? low : value > high ? high : value; }

double ssProfile_Next(ssProfile* p) {
  if (p == NULL) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "profile = NULL: no profile to draw a frame from");
    return NAN;
  }
  long index = p->frame_index++;
  switch (p->kind) {
    case SS_PROFILE_FIXED:
      return p->a_s;
    case SS_PROFILE_UNIFORM:
      return clamp(p->a_s + (p->b_s - p->a_s) * ssRngUniform(&p->rng), p->a_s, p->b_s);
    case SS_PROFILE_JITTER: {
      /* Redrawing outside three deviations keeps the distribution symmetric, so the mean stays 1/FPS. */
      double z;
      do z = ssRngNormal(&p->rng);
      while (fabs(z) > 3.0);
      return clamp(p->a_s + p->b_s * z, p->a_s - 3.0 * p->b_s, p->a_s + 3.0 * p->b_s);
    }
    case SS_PROFILE_HITCH:
      return (index + 1) % p->every == 0 ? p->b_s : p->a_s;
    case SS_PROFILE_VSYNC:
      /* The first frame runs at rate A; every later one switches with probability 1/10. */
      if (index > 0 && ssRngUniform(&p->rng) < 0.1) p->on_b = !p->on_b;
      return p->on_b ? p->b_s : p->a_s;
    case SS_PROFILE_TRACE:
      return p->trace_s[index % p->trace_count];
  }
  return p->a_s;
}

double ssProfileMeanFrame(const ssProfile* p) {
  switch (p->kind) {
    case SS_PROFILE_FIXED:
    case SS_PROFILE_JITTER:
      return p->a_s;
    case SS_PROFILE_UNIFORM:
    case SS_PROFILE_VSYNC: /* switching both ways with the same probability spends half the frames at each rate */
      return 0.5 * (p->a_s + p->b_s);
    case SS_PROFILE_HITCH:
      return p->a_s + (p->b_s - p->a_s) / (double)p->every;
    case SS_PROFILE_TRACE: {
      double sum = 0;
      for (long i = 0; i < p->trace_count; ++i) sum += p->trace_s[i];
      return sum / (double)p->trace_count;
    }
  }
  return p->a_s;
}
