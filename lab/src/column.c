/* A quantity's name in a table (CSV header, JSON columns): one spelling, made here from the scene's quantity name and
 * unit, so that the C example, the lab and the Python package never type it twice. Names hold only letters, digits
 * and '_', so any CSV reader, spreadsheet or dataframe takes them as they are. */
#include <stdio.h>
#include <string.h>

#include "lab_error.h"
#include "steadystep/lab/scene.h"

/* Appends text to out at *length, counting on past size (as snprintf) but writing only what fits. */
static void put(char* out, size_t size, size_t* length, const char* text) {
  for (; *text != '\0'; ++text, ++*length)
    if (*length + 1 < size) out[*length] = *text;
}

/* Appends text spelled for a column name. */
static void putSpelled(char* out, size_t size, size_t* length, const char* text) {
  for (; *text != '\0'; ++text) {
    char c = *text;
    if (c == '/') put(out, size, length, "_per_");
    else if (c == ' ' || c == '*' || c == '-') put(out, size, length, "_");
    else if (c == '(' || c == ')' || c == '^') continue;
    else put(out, size, length, (char[2]){c, '\0'});
  }
}

int ssColumnName(const char* name, const char* unit, char* out, size_t size) {
  if (name == NULL || unit == NULL || (out == NULL && size > 0)) {
    ssLabFail(SS_ERROR_OUT_OF_RANGE, "%s = NULL: ssColumnName needs a name, a unit and somewhere to write",
              name == NULL ? "name" : unit == NULL ? "unit" : "out");
    return -1;
  }
  size_t length = 0;
  putSpelled(out, size, &length, name);
  if (unit[0] != '\0') {
    put(out, size, &length, "_");
    putSpelled(out, size, &length, unit);
  }
  if (size > 0) out[length < size ? length : size - 1] = '\0';
  return (int)length;
}
