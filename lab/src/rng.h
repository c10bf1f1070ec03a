/* Internal: a small seeded pseudo-random generator (xoshiro256** seeded by splitmix64).
 *
 * Profiles must be reproducible from their seed on every machine, so they use this instead of rand(). */
#ifndef STEADYSTEP_RNG_H
#define STEADYSTEP_RNG_H

#include <stdint.h>

typedef struct ssRng {
  uint64_t state[4];
} ssRng;

/* Seeds the generator; every seed (0 included) gives a full-period state. */
void ssRngSeed(ssRng* rng, uint64_t seed);

/* The next 64 random bits. */
uint64_t ssRngNext(ssRng* rng);

/* Uniform in [0, 1), 53 random bits. */
double ssRngUniform(ssRng* rng);

/* Standard normal (mean 0, deviation 1), Marsaglia's polar method: no trigonometry, so the same on every libm. */
double ssRngNormal(ssRng* rng);

#endif
