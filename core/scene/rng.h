/* Small deterministic pseudo-random number generator.
 *
 * xoshiro256** (Blackman & Vigna, "Scrambled linear pseudorandom number
 * generators", ACM TOMS 2021) seeded through splitmix64 (Steele, Lea & Flood,
 * "Fast splittable pseudorandom number generators", OOPSLA 2014), so any
 * 64-bit seed, 0 included, gives a well-mixed state. The stream depends only
 * on the seed: the same seed gives the same numbers on every platform.
 *
 * Not thread-safe per generator; give each thread its own Rng (e.g. seeded
 * with rng_mix(seed, thread_or_item_index)). */
#ifndef MPM_RNG_H
#define MPM_RNG_H

#include <stdint.h>

typedef struct {
    uint64_t s[4];
} Rng;

/* One splitmix64 step: advances *x and returns a mixed 64-bit value. */
static inline uint64_t rng_splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Combines a seed and a stream index into one well-mixed seed (for
 * independent sub-streams: per object, per particle, ...). */
static inline uint64_t rng_mix(uint64_t seed, uint64_t index)
{
    uint64_t x = seed ^ (index * 0xD1B54A32D192ED03ull + 0x8CB92BA72F3D8DD7ull);
    return rng_splitmix64(&x);
}

static inline void rng_seed(Rng *r, uint64_t seed)
{
    uint64_t x = seed;
    for (int k = 0; k < 4; ++k) r->s[k] = rng_splitmix64(&x);
}

static inline uint64_t rng_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

/* xoshiro256**: next 64 random bits. */
static inline uint64_t rng_u64(Rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = rng_rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rng_rotl(s[3], 45);
    return result;
}

/* Uniform double in [0, 1) with 53 random bits. */
static inline double rng_double(Rng *r) { return (double)(rng_u64(r) >> 11) * (1.0 / 9007199254740992.0); }

/* Uniform double in [lo, hi). */
static inline double rng_uniform(Rng *r, double lo, double hi) { return lo + (hi - lo) * rng_double(r); }

/* Uniform integer in [0, n) for 1 <= n <= 2^53. */
static inline uint64_t rng_below(Rng *r, uint64_t n)
{
    uint64_t k = (uint64_t)(rng_double(r) * (double)n);
    return k < n ? k : n - 1;
}

#endif
