/* What every benchmark shares: the clock it times with, and how a failed call ends it. */
#ifndef BENCH_COMMON_H
#define BENCH_COMMON_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <steadystep/status.h>

/* This thread's CPU time (s), not the wall clock: on a machine shared with other work, the time the thread waits for
 * a core would otherwise land on whichever copy happened to be timed. */
static inline double benchCpuSeconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Ends the benchmark with the library's message when a call it needs failed. */
static inline void benchCheck(const char* bench, ssStatus status, const char* what) {
  if (status == SS_OK) return;
  fprintf(stderr, "%s: %s: %s\n", bench, what, ssLastError());
  exit(1);
}

#endif
