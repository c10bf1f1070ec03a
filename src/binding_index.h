/* Internal: where a binding is, found in constant time. The registry keeps its bindings in arrays (Apply streams
 * through them in binding order); this index maps an ODE object and a small tag (a joint row's parameter set and
 * axis; 0 for a body) to the binding's position, so that binding and adopting n rows costs O(n), not O(n²). */
#ifndef STEADYSTEP_BINDING_INDEX_H
#define STEADYSTEP_BINDING_INDEX_H

#include <stddef.h>

typedef struct ssIndexSlot {
  const void* object;
  int tag;
  int position; /* -1: empty */
} ssIndexSlot;

/* Open addressing with linear probing, kept at most half full. A zeroed index is empty and valid. */
typedef struct ssBindingIndex {
  ssIndexSlot* slots;
  size_t capacity; /* a power of two, or 0 */
  size_t count;
} ssBindingIndex;

/* Makes room for `count` entries in all, so that inserting up to that many cannot fail. Returns 0 (the index as it
 * was) when out of memory. */
int ssIndexReserve(ssBindingIndex* index, size_t count);

/* The position stored for (object, tag), or -1. */
int ssIndexFind(const ssBindingIndex* index, const void* object, int tag);

/* Stores position for (object, tag), replacing any position stored for it. Room must have been reserved. */
void ssIndexPut(ssBindingIndex* index, const void* object, int tag, int position);

/* Removes (object, tag) if present. */
void ssIndexRemove(ssBindingIndex* index, const void* object, int tag);

/* Empties the index, keeping its room. */
void ssIndexClear(ssBindingIndex* index);

void ssIndexFree(ssBindingIndex* index);

#endif
