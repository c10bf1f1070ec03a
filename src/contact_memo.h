/* Internal: the last contact a stepper softened in a step, as the program gave it and as it was written. A near
 * callback gives most contacts the same surface, and a contact's softness depends on nothing else (contact.c): the
 * next contacts with that surface, and a finite geometry, are written from here, with no law and no check repeated.
 * Inline: every contact of every step passes here. */
#ifndef STEADYSTEP_CONTACT_MEMO_H
#define STEADYSTEP_CONTACT_MEMO_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <ode/ode.h>

#if defined(__SSE2__) && defined(dDOUBLE)
#include <emmintrin.h>
#endif

#if defined(dDOUBLE)
typedef uint64_t ssRealBits;
#else
typedef uint32_t ssRealBits;
#endif

typedef struct ssContactMemo {
  unsigned stale; /* 1 from the start of every step (the step's length, the mapping or the tuned world changed): fits
                   * nothing; 0 once a contact is taken */
  int mode_in, mode_out;
  ssRealBits erp_in, cfm_in;     /* the given soft_erp and soft_cfm, as bits */
  ssRealBits erp_mask, cfm_mask; /* all ones where mode_in uses the value, 0 where any value is the same surface */
  dReal erp_out, cfm_out;
  int rewrites; /* whether the written surface differs from the given one (naive's does not) */
  int* counter; /* the count the contacts served as this one are added to */
} ssContactMemo;

static inline ssRealBits ssBitsOf(dReal value) {
  ssRealBits bits;
  memcpy(&bits, &value, sizeof bits);
  return bits;
}

/* The memo of a contact given with surface `given` and softened to `written`, counted in *counter. */
static inline void ssContactMemoTake(ssContactMemo* memo, const dSurfaceParameters* given,
                                     const dSurfaceParameters* written, int* counter) {
  *memo = (ssContactMemo){.stale = 0,
                          .mode_in = given->mode,
                          .mode_out = written->mode,
                          .erp_in = ssBitsOf(given->soft_erp),
                          .cfm_in = ssBitsOf(given->soft_cfm),
                          .erp_mask = (given->mode & dContactSoftERP) ? ~(ssRealBits)0 : 0,
                          .cfm_mask = (given->mode & dContactSoftCFM) ? ~(ssRealBits)0 : 0,
                          .erp_out = written->soft_erp,
                          .cfm_out = written->soft_cfm,
                          .counter = counter};
  memo->rewrites = memo->mode_out != memo->mode_in || ssBitsOf(memo->erp_out) != memo->erp_in ||
                   ssBitsOf(memo->cfm_out) != memo->cfm_in;
}

/* Whether each of contacts[count] has the memo's surface (the values its mode uses, bit for bit: a memo is made only
 * from values the slow path took, so no NaN matches; -0 for 0 takes the slow path) and a finite geometry: their
 * positions, normals and depths summed, less themselves, are 0 only when each is finite (an overflowing sum says no
 * for finite values, and the slow path checks each, contact.c). One pass, no branch a contact; with SSE2 and double
 * precision soft_erp and soft_cfm (one after the other in dSurfaceParameters) are compared in one register, and the
 * geometry's x and y summed in another. */
#if defined(__SSE2__) && defined(dDOUBLE)
_Static_assert(offsetof(dSurfaceParameters, soft_cfm) == offsetof(dSurfaceParameters, soft_erp) + sizeof(dReal),
               "soft_erp and soft_cfm are read as one pair");
static inline int ssContactMemoFits(const ssContactMemo* memo, const dContact* contacts, int count) {
  const __m128i soft_in = _mm_set_epi64x((long long)memo->cfm_in, (long long)memo->erp_in);
  __m128i soft_differs = _mm_setzero_si128(); /* masked once, after the pass */
  __m128d pos_normal_xy = _mm_setzero_pd();
  double pos_z = 0, normal_z = 0, depth = 0;
  unsigned mode_differs = memo->stale;
  for (const dContact *contact = contacts, *end = contacts + count; contact != end; ++contact) {
    const dSurfaceParameters* surface = &contact->surface;
    const dContactGeom* geom = &contact->geom;
    __m128i soft = _mm_loadu_si128((const __m128i*)(const void*)&surface->soft_erp);
    soft_differs = _mm_or_si128(soft_differs, _mm_xor_si128(soft, soft_in));
    mode_differs |= (unsigned)(surface->mode ^ memo->mode_in);
    pos_normal_xy = _mm_add_pd(pos_normal_xy, _mm_add_pd(_mm_loadu_pd(geom->pos), _mm_loadu_pd(geom->normal)));
    pos_z += geom->pos[2];
    normal_z += geom->normal[2];
    depth += geom->depth;
  }
  const __m128i soft_mask = _mm_set_epi64x((long long)memo->cfm_mask, (long long)memo->erp_mask);
  soft_differs = _mm_or_si128(_mm_and_si128(soft_differs, soft_mask), _mm_cvtsi32_si128((int)mode_differs));
  const __m128i same = _mm_cmpeq_epi32(soft_differs, _mm_setzero_si128());
  /* every sum in both lanes; x - x is 0 where x is finite and NaN where it is not, and only NaN is unordered */
  const __m128d sums = _mm_add_pd(pos_normal_xy, _mm_set1_pd(pos_z + normal_z + depth));
  const __m128d zero_if_finite = _mm_sub_pd(sums, sums);
  const __m128d finite = _mm_cmpord_pd(zero_if_finite, zero_if_finite);
  return _mm_movemask_epi8(_mm_and_si128(same, _mm_castpd_si128(finite))) == 0xffff;
}
#else
static inline int ssContactMemoFits(const ssContactMemo* memo, const dContact* contacts, int count) {
  ssRealBits differs = 0;
  double sum = 0;
  for (int i = 0; i < count; ++i) {
    const dSurfaceParameters* surface = &contacts[i].surface;
    const dContactGeom* geom = &contacts[i].geom;
    differs |= ((ssBitsOf(surface->soft_erp) ^ memo->erp_in) & memo->erp_mask) |
               ((ssBitsOf(surface->soft_cfm) ^ memo->cfm_in) & memo->cfm_mask) |
               (ssRealBits)(unsigned)(surface->mode ^ memo->mode_in);
    sum += (double)geom->depth + geom->pos[0] + geom->pos[1] + geom->pos[2] + geom->normal[0] + geom->normal[1] +
           geom->normal[2];
  }
  return !memo->stale & (differs == 0) & (sum - sum == 0.0);
}
#endif

/* ssContactMemoFits for one contact, without the pairs' setup. */
static inline int ssContactMemoFitsOne(const ssContactMemo* memo, const dContact* contact) {
  const dSurfaceParameters* surface = &contact->surface;
  const dContactGeom* geom = &contact->geom;
  ssRealBits differs = ((ssBitsOf(surface->soft_erp) ^ memo->erp_in) & memo->erp_mask) |
                       ((ssBitsOf(surface->soft_cfm) ^ memo->cfm_in) & memo->cfm_mask);
  double sum = (double)geom->depth + geom->pos[0] + geom->pos[1] + geom->pos[2] + geom->normal[0] + geom->normal[1] +
               geom->normal[2];
  return !memo->stale & (surface->mode == memo->mode_in) & (differs == 0) & (sum - sum == 0.0);
}

/* Writes the memo's softness into contacts[count], which fit it. */
static inline void ssContactMemoWrite(const ssContactMemo* memo, dContact* contacts, int count) {
  if (!memo->rewrites) return;
  for (int i = 0; i < count; ++i) {
    contacts[i].surface.mode = memo->mode_out;
    contacts[i].surface.soft_erp = memo->erp_out;
    contacts[i].surface.soft_cfm = memo->cfm_out;
  }
}

#endif
