/* What every benchmark shares: the clock it times with, how a failed call ends it, and the medians it prints. */
#ifndef BENCH_COMMON_H
#define BENCH_COMMON_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include <steadystep/status.h>

/* This thread's CPU time (s), not the wall clock: on a machine shared with other work, the time the thread waits for
 * a core would otherwise land on whichever copy happened to be timed. */
static inline double benchCpuSeconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Prints what the figures were measured on, one line: the load average over 1, 5 and 15 minutes (the threads that
 * wanted a core: above the cores, this benchmark shared them with other work) and the cores online. when says at
 * which point of the benchmark ("before", "after"). */
static inline void benchPrintMachine(const char* bench, const char* when) {
  double load[3] = {-1, -1, -1};
  if (getloadavg(load, 3) != 3) load[0] = load[1] = load[2] = -1;
  printf("%s: load average %.2f %.2f %.2f %s, %ld cores online\n", bench, load[0], load[1], load[2], when,
         sysconf(_SC_NPROCESSORS_ONLN));
}

/* Ends the benchmark with the library's message when a call it needs failed. */
static inline void benchCheck(const char* bench, ssStatus status, const char* what) {
  if (status == SS_OK) return;
  fprintf(stderr, "%s: %s: %s\n", bench, what, ssLastError());
  exit(1);
}

static inline int benchCompareDoubles(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

/* Sorts values in place, smallest first (their range is then values[0] to values[count - 1]). */
static inline void benchSort(double* values, int count) {
  qsort(values, (size_t)count, sizeof(double), benchCompareDoubles);
}

/* The median of count > 0 values (the upper one of an even count), sorting them in place. */
static inline double benchMedian(double* values, int count) {
  benchSort(values, count);
  return values[count / 2];
}

/* Where the median of the population count sorted values were drawn from lies, with 95 % confidence: between the
 * order statistics the sign test gives (sorted[k - 1] and sorted[count - k] for the largest k with P(B <= k - 1) at
 * most 2.5 %, B binomial over count draws of 1/2), which assumes nothing of the values' distribution. Below 6 values
 * no interval is that sure: their whole range. */
static inline void benchMedianInterval(const double* sorted, int count, double* low, double* high) {
  double term = 1, at_most = 0; /* P(B = j) and P(B <= j - 1), as k = j + 1 grows */
  for (int j = 0; j < count; ++j) term *= 0.5;
  int k = 0;
  while (k < count / 2 && at_most + term <= 0.025) {
    at_most += term;
    term *= (double)(count - k) / (k + 1);
    ++k;
  }
  *low = sorted[k > 0 ? k - 1 : 0];
  *high = sorted[k > 0 ? count - k : count - 1];
}

#endif
