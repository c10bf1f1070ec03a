/* The core's one pointer set (pointer_set.h). */
#include "pointer_set.h"

#include <stdint.h>
#include <stdlib.h>

/* Objects made together lie near each other: the low bits of their addresses repeat, so the address is mixed (its
 * 16-byte granule, and the page above it folded in) before it picks a slot. */
static size_t slotOf(const void* pointer, size_t capacity) {
  uint64_t address = (uint64_t)(uintptr_t)pointer;
  return (size_t)((address >> 4) + ((address >> 20) * 0x9E3779B97F4A7C15ull >> 32)) & (capacity - 1);
}

static size_t probe(const ssPointerSet* set, const void* pointer) {
  size_t slot = slotOf(pointer, set->capacity);
  while (set->slots[slot] != NULL && set->slots[slot] != pointer) slot = (slot + 1) & (set->capacity - 1);
  return slot;
}

int ssPointerSetAdd(ssPointerSet* set, const void* pointer) {
  if (2 * (set->count + 1) > set->capacity) { /* kept at most half full */
    size_t capacity = set->capacity ? 2 * set->capacity : 64;
    const void** slots = calloc(capacity, sizeof *slots);
    if (slots == NULL) return -1;
    ssPointerSet grown = {slots, capacity, set->count};
    for (size_t i = 0; i < set->capacity; ++i)
      if (set->slots[i] != NULL) slots[probe(&grown, set->slots[i])] = set->slots[i];
    free(set->slots);
    *set = grown;
  }
  size_t slot = probe(set, pointer);
  if (set->slots[slot] == pointer) return 0;
  set->slots[slot] = pointer;
  set->count += 1;
  return 1;
}

int ssPointerSetHas(const ssPointerSet* set, const void* pointer) {
  return set->capacity > 0 && pointer != NULL && set->slots[probe(set, pointer)] == pointer;
}

void ssPointerSetFree(ssPointerSet* set) {
  free(set->slots);
  *set = (ssPointerSet){NULL, 0, 0};
}

static size_t probeKey(const ssPointerMap* map, const void* key) {
  size_t slot = slotOf(key, map->capacity);
  while (map->keys[slot] != NULL && map->keys[slot] != key) slot = (slot + 1) & (map->capacity - 1);
  return slot;
}

int ssPointerMapPut(ssPointerMap* map, const void* key, int value) {
  if (2 * (map->count + 1) > map->capacity) { /* kept at most half full */
    size_t capacity = map->capacity ? 2 * map->capacity : 64;
    ssPointerMap grown = {calloc(capacity, sizeof(void*)), malloc(capacity * sizeof(int)), capacity, map->count};
    if (grown.keys == NULL || grown.values == NULL) {
      free(grown.keys);
      free(grown.values);
      return -1;
    }
    for (size_t i = 0; i < map->capacity; ++i) {
      if (map->keys[i] == NULL) continue;
      size_t slot = probeKey(&grown, map->keys[i]);
      grown.keys[slot] = map->keys[i];
      grown.values[slot] = map->values[i];
    }
    free(map->keys);
    free(map->values);
    *map = grown;
  }
  size_t slot = probeKey(map, key);
  int added = map->keys[slot] == NULL;
  map->keys[slot] = key;
  map->values[slot] = value;
  map->count += (size_t)added;
  return added;
}

int ssPointerMapGet(const ssPointerMap* map, const void* key, int missing) {
  if (map->capacity == 0 || key == NULL) return missing;
  size_t slot = probeKey(map, key);
  return map->keys[slot] == key ? map->values[slot] : missing;
}

/* Linear probing's deletion: the entries after the hole that could sit in it move back, so no search stops early. */
void ssPointerMapRemove(ssPointerMap* map, const void* key) {
  if (map->capacity == 0 || key == NULL) return;
  size_t mask = map->capacity - 1, hole = probeKey(map, key);
  if (map->keys[hole] != key) return;
  for (size_t next = (hole + 1) & mask; map->keys[next] != NULL; next = (next + 1) & mask) {
    size_t home = slotOf(map->keys[next], map->capacity);
    /* next stays unless its home lies cyclically outside (hole, next] */
    if (((next - home) & mask) < ((next - hole) & mask)) continue;
    map->keys[hole] = map->keys[next];
    map->values[hole] = map->values[next];
    hole = next;
  }
  map->keys[hole] = NULL;
  map->count -= 1;
}

void ssPointerMapFree(ssPointerMap* map) {
  free(map->keys);
  free(map->values);
  *map = (ssPointerMap){NULL, NULL, 0, 0};
}

int ssCompareHandles(const void* a, const void* b) {
  uintptr_t x = (uintptr_t) * (const void* const*)a, y = (uintptr_t) * (const void* const*)b;
  return (x > y) - (x < y);
}
