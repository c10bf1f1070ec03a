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

/* How two handles order by address (qsort and bsearch): -1, 0 or 1. */
int ssCompareHandles(const void* a, const void* b);

#endif
