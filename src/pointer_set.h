/* Internal: a set of pointers (ODE's handles), by open addressing: the one the core uses wherever it must know
 * whether it has met an object (adoption's walk, the known bodies' walk, the live joints and bodies after a
 * program destroyed some). Nothing is read through the pointers. */
#ifndef STEADYSTEP_POINTER_SET_H
#define STEADYSTEP_POINTER_SET_H

#include <stddef.h>

typedef struct ssPointerSet {
  const void** slots; /* NULL: empty */
  size_t capacity;    /* a power of two, or 0 */
  size_t count;
} ssPointerSet;

/* Adds pointer (not NULL): 1 if it was new, 0 if there already, -1 when out of memory (the set as it was). */
int ssPointerSetAdd(ssPointerSet* set, const void* pointer);

/* Whether pointer is in the set. */
int ssPointerSetHas(const ssPointerSet* set, const void* pointer);

/* Empties the set and frees its memory. */
void ssPointerSetFree(ssPointerSet* set);

/* A map from pointers (ODE's handles) to ints, by open addressing: the known bodies' places in their list, the
 * adopted spaces' bodies with their geom counts. Nothing is read through the pointers. */
typedef struct ssPointerMap {
  const void** keys; /* NULL: empty */
  int* values;
  size_t capacity; /* a power of two, or 0 */
  size_t count;
} ssPointerMap;

/* Sets key's (not NULL) value: 1 if the key was new, 0 if it was there (its value replaced), -1 when out of memory
 * (the map as it was). */
int ssPointerMapPut(ssPointerMap* map, const void* key, int value);

/* key's value, or missing when key is not in the map. */
int ssPointerMapGet(const ssPointerMap* map, const void* key, int missing);

/* Takes key out of the map (nothing when it is not there). */
void ssPointerMapRemove(ssPointerMap* map, const void* key);

/* Empties the map and frees its memory. */
void ssPointerMapFree(ssPointerMap* map);

/* How two handles order by address (qsort and bsearch): -1, 0 or 1. */
int ssCompareHandles(const void* a, const void* b);

#endif
