/* xoshiro256** (Blackman and Vigna, 2018), seeded through splitmix64 as its authors recommend, so that nearby
 * seeds give unrelated streams and the all-zero state cannot occur. */
#include "rng.h"

#include <math.h>

static uint64_t splitmix64(uint64_t* x) {
  uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

void ssRngSeed(ssRng* rng, uint64_t seed) {
  uint64_t x = seed;
  for (int i = 0; i < 4; ++i) rng->state[i] = splitmix64(&x);
}

uint64_t ssRngNext(ssRng* rng) {
  uint64_t* s = rng->state;
  uint64_t result = rotl(s[1] * 5, 7) * 9;
  uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return result;
}

double ssRngUniform(ssRng* rng) { return (double)(ssRngNext(rng) >> 11) * 0x1.0p-53; }

double ssRngNormal(ssRng* rng) {
  for (;;) {
    double u = 2.0 * ssRngUniform(rng) - 1.0;
    double v = 2.0 * ssRngUniform(rng) - 1.0;
    double s = u * u + v * v;
    if (s > 0.0 && s < 1.0) return u * sqrt(-2.0 * log(s) / s);
  }
}
