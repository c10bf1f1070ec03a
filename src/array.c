#include "array.h"

#include <stdlib.h>

int ssReserveOne(void** items, int count, int* capacity, size_t size) {
  if (count < *capacity) return 1;
  int grown = *capacity ? 2 * *capacity : 8;
  void* larger = realloc(*items, (size_t)grown * size);
  if (larger == NULL) return 0;
  *items = larger;
  *capacity = grown;
  return 1;
}
