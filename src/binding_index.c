/* The bindings' index: open addressing on (object, tag), linear probing, deletion by backward shift (no tombstones,
 * so lookups stay short after many unbindings). */
#include "binding_index.h"

#include <stdint.h>
#include <stdlib.h>

/* ODE allocates a world's objects one after the other: within a megabyte, the home slot follows the address (objects
 * made together are looked up together, e.g. by adoption, and share cache lines of the index), and megabytes are
 * scattered by a multiplicative hash. The tag (a row's parameter set and axis, < 16) is an offset from the home of
 * its object, whose neighbours are at least a few dozen slots away. */
static size_t homeSlot(const void* object, int tag, size_t capacity) {
  uint64_t address = (uint64_t)(uintptr_t)object;
  uint64_t region = (address >> 20) * 0x9E3779B97F4A7C15ull;
  return (size_t)((address >> 4) + (uint64_t)(unsigned)tag + (region >> 32)) & (capacity - 1);
}

/* The slot holding (object, tag), or the empty slot where it would go. */
static size_t probe(const ssBindingIndex* index, const void* object, int tag) {
  size_t mask = index->capacity - 1, j = homeSlot(object, tag, index->capacity);
  while (index->slots[j].position >= 0 && (index->slots[j].object != object || index->slots[j].tag != tag))
    j = (j + 1) & mask;
  return j;
}

int ssIndexReserve(ssBindingIndex* index, size_t count) {
  if (2 * count <= index->capacity) return 1;
  size_t capacity = index->capacity ? index->capacity : 16;
  while (2 * count > capacity) capacity *= 2;
  ssIndexSlot* slots = malloc(capacity * sizeof *slots);
  if (slots == NULL) return 0;
  for (size_t j = 0; j < capacity; ++j) slots[j].position = -1;
  ssBindingIndex larger = {slots, capacity, 0};
  for (size_t j = 0; j < index->capacity; ++j)
    if (index->slots[j].position >= 0)
      ssIndexPut(&larger, index->slots[j].object, index->slots[j].tag, index->slots[j].position);
  free(index->slots);
  *index = larger;
  return 1;
}

int ssIndexFind(const ssBindingIndex* index, const void* object, int tag) {
  if (index->capacity == 0) return -1;
  return index->slots[probe(index, object, tag)].position;
}

void ssIndexPut(ssBindingIndex* index, const void* object, int tag, int position) {
  size_t j = probe(index, object, tag);
  if (index->slots[j].position < 0) index->count += 1;
  index->slots[j] = (ssIndexSlot){object, tag, position};
}

void ssIndexRemove(ssBindingIndex* index, const void* object, int tag) {
  if (index->capacity == 0) return;
  size_t mask = index->capacity - 1, hole = probe(index, object, tag);
  if (index->slots[hole].position < 0) return;
  index->slots[hole].position = -1;
  index->count -= 1;
  /* entries after the hole that probed past it move back into it, so that every entry stays reachable */
  for (size_t j = (hole + 1) & mask; index->slots[j].position >= 0; j = (j + 1) & mask) {
    size_t home = homeSlot(index->slots[j].object, index->slots[j].tag, index->capacity);
    int reaches_hole = hole <= j ? (home <= hole || home > j) : (home <= hole && home > j);
    if (!reaches_hole) continue;
    index->slots[hole] = index->slots[j];
    index->slots[j].position = -1;
    hole = j;
  }
}

void ssIndexClear(ssBindingIndex* index) {
  for (size_t j = 0; j < index->capacity; ++j) index->slots[j].position = -1;
  index->count = 0;
}

void ssIndexFree(ssBindingIndex* index) {
  free(index->slots);
  *index = (ssBindingIndex){NULL, 0, 0};
}
