/* Counter-based hashing RNG (SplitMix64 finaliser over a mixed key). */
#include "base/rng.h"

#include <math.h>

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

uint64_t fs_hash3(uint64_t seed, uint32_t purpose, uint64_t index)
{
    uint64_t h = mix64(seed + UINT64_C(0x9e3779b97f4a7c15));
    h = mix64(h ^ ((uint64_t)purpose * UINT64_C(0xd6e8feb86659fd93)));
    return mix64(h ^ (index + UINT64_C(0x632be59bd9b4e019)));
}

double fs_rand01(uint64_t seed, uint32_t purpose, uint64_t index)
{
    return (double)(fs_hash3(seed, purpose, index) >> 11) * 0x1.0p-53;
}

double fs_rand_range(uint64_t seed, uint32_t purpose, uint64_t index, double lo, double hi)
{
    return lo + (hi - lo) * fs_rand01(seed, purpose, index);
}

double fs_rand_normal(uint64_t seed, uint32_t purpose, uint64_t index)
{
    double u1 = fs_rand01(seed, purpose, 2 * index);
    double u2 = fs_rand01(seed, purpose, 2 * index + 1);
    if (u1 < 1e-300)
        u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}
