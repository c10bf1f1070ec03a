/* Internal: asking for a large world's memory ahead of a pass over its bodies. After ODE's step or the program's
 * frame, a world of many bodies is out of cache, and a pass that asks for the bodies a few places ahead overlaps
 * their loads instead of waiting for one after the other. */
#ifndef STEADYSTEP_PREFETCH_H
#define STEADYSTEP_PREFETCH_H

/* A hint that memory is read soon (GCC, clang); nothing elsewhere. */
#if defined(__GNUC__)
#define SS_PREFETCH(address) __builtin_prefetch(address)
#else
#define SS_PREFETCH(address) ((void)(address))
#endif

/* How many bodies ahead a pass asks for a body's memory, and from how many bodies on (a list that stays in cache
 * needs none). */
enum { kPrefetchAhead = 8, kPrefetchFrom = 256 };

/* Up to which body a pass over count bodies asks for the one kPrefetchAhead ahead: none below kPrefetchFrom. */
static inline int ssPrefetchUntil(int count) { return count >= kPrefetchFrom ? count - kPrefetchAhead : 0; }

#endif
