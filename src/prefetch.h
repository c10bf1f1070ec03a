/* Internal: asking for a large world's memory ahead of a pass over its bodies. After ODE's step or the program's
 * frame, a world of many bodies is out of cache, and a pass that asks for the bodies a few places ahead overlaps
 * their loads instead of waiting for one after the other. */
#ifndef STEADYSTEP_PREFETCH_H
#define STEADYSTEP_PREFETCH_H

/* A hint that memory is read soon (GCC, clang); nothing elsewhere. A helper made of hints alone is declared with
 * SS_PREFETCH_HELPER: always inlined, since GCC takes such a function for one without effect and drops its calls (as
 * it did: the known bodies' passes asked for no body ahead until this was seen in the compiled code). */
#if defined(__GNUC__)
#define SS_PREFETCH(address) __builtin_prefetch(address)
#define SS_PREFETCH_HELPER static inline __attribute__((always_inline))
#else
#define SS_PREFETCH(address) ((void)(address))
#define SS_PREFETCH_HELPER static inline
#endif

/* How many bodies ahead a pass asks for a body's memory, and from how many bodies on: a list that stays in cache
 * needs none, and a pass reads about 300 bytes a body (its entries, and the head, state and accumulators of ODE's
 * body), so a core's L2 cache of 1 MiB holds some 3,000. */
enum { kPrefetchAhead = 8, kPrefetchFrom = 4096 };

/* Up to which body a pass over count bodies asks for the one kPrefetchAhead ahead: none below kPrefetchFrom. */
static inline int ssPrefetchUntil(int count) { return count >= kPrefetchFrom ? count - kPrefetchAhead : 0; }

#endif
