/* Internal: growing an array one item at a time. */
#ifndef STEADYSTEP_ARRAY_H
#define STEADYSTEP_ARRAY_H

#include <stddef.h>

/* Makes room for one more item of `size` bytes in *items, which holds count of *capacity, doubling the capacity
 * when full. Returns 0 (and leaves everything as it was) when out of memory. */
int ssReserveOne(void** items, int count, int* capacity, size_t size);

#endif
