/* Gradient noise in 2-D (optionally periodic) and 3-D with hashed lattice gradients. */
#include "field/noise.h"

#include <math.h>

#include "base/rng.h"
#include "base/vec.h"

/* design: classic gradient noise. Every integer lattice point gets a pseudo-random unit gradient
 * g = fs_hash3(seed, FS_RNG_NOISE, packed lattice index); the value at a point is the blend of the
 * four (eight) corner contributions g . (p - corner) with the quintic fade 6t^5 - 15t^4 + 10t^3,
 * so the field is C2, zero at every lattice point, and depends on nothing but (seed, position).
 * Periodicity comes from reducing lattice indices modulo the period before hashing. With unit
 * gradients the extreme values are sqrt(n)/2 in n dimensions; the result is scaled by 2/sqrt(n)
 * so it lies in about [-1, 1]. */

static double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

static double lerp(double a, double b, double t) { return a + (b - a) * t; }

static int64_t wrap_index(int64_t i, int period)
{
    if (period <= 0)
        return i;
    int64_t r = i % period;
    return r < 0 ? r + period : r;
}

/* Two hashed uniforms in [0, 1) from one 64-bit hash (32 bits each). */
static void hash_uniforms(uint64_t h, double *a, double *b)
{
    *a = (double)(h >> 32) * 0x1.0p-32;
    *b = (double)(h & UINT64_C(0xffffffff)) * 0x1.0p-32;
}

static void gradient2(uint64_t seed, int64_t ix, int64_t iy, double *g)
{
    uint64_t key = ((uint64_t)(uint32_t)ix) | ((uint64_t)(uint32_t)iy << 32);
    double a, b;
    hash_uniforms(fs_hash3(seed, FS_RNG_NOISE, key), &a, &b);
    double angle = 2.0 * FS_PI * a;
    g[0] = cos(angle);
    g[1] = sin(angle);
}

static void gradient3(uint64_t seed, int64_t ix, int64_t iy, int64_t iz, double *g)
{
    const uint64_t mask = (UINT64_C(1) << 21) - 1;
    uint64_t key = ((uint64_t)ix & mask) | (((uint64_t)iy & mask) << 21) | (((uint64_t)iz & mask) << 42)
                   | (UINT64_C(1) << 63);
    double a, b;
    hash_uniforms(fs_hash3(seed, FS_RNG_NOISE, key), &a, &b);
    double z = 2.0 * a - 1.0;
    double r = sqrt(1.0 - z * z);
    double angle = 2.0 * FS_PI * b;
    g[0] = r * cos(angle);
    g[1] = r * sin(angle);
    g[2] = z;
}

double fs_noise2(uint64_t seed, double x, double y, int period_x, int period_y)
{
    double fx = floor(x), fy = floor(y);
    double tx = x - fx, ty = y - fy;
    int64_t x0 = (int64_t)fx, y0 = (int64_t)fy;
    int64_t ix[2] = {wrap_index(x0, period_x), wrap_index(x0 + 1, period_x)};
    int64_t iy[2] = {wrap_index(y0, period_y), wrap_index(y0 + 1, period_y)};
    double v[2][2];
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            double g[2];
            gradient2(seed, ix[i], iy[j], g);
            v[j][i] = g[0] * (tx - i) + g[1] * (ty - j);
        }
    double sx = fade(tx), sy = fade(ty);
    return sqrt(2.0) * lerp(lerp(v[0][0], v[0][1], sx), lerp(v[1][0], v[1][1], sx), sy);
}

double fs_noise3(uint64_t seed, double x, double y, double z)
{
    double f[3] = {floor(x), floor(y), floor(z)};
    double t[3] = {x - f[0], y - f[1], z - f[2]};
    int64_t i0[3] = {(int64_t)f[0], (int64_t)f[1], (int64_t)f[2]};
    double v[2][2][2];
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                double g[3];
                gradient3(seed, i0[0] + i, i0[1] + j, i0[2] + k, g);
                v[k][j][i] = g[0] * (t[0] - i) + g[1] * (t[1] - j) + g[2] * (t[2] - k);
            }
    double s[3] = {fade(t[0]), fade(t[1]), fade(t[2])};
    double a = lerp(lerp(v[0][0][0], v[0][0][1], s[0]), lerp(v[0][1][0], v[0][1][1], s[0]), s[1]);
    double b = lerp(lerp(v[1][0][0], v[1][0][1], s[0]), lerp(v[1][1][0], v[1][1][1], s[0]), s[1]);
    return 2.0 / sqrt(3.0) * lerp(a, b, s[2]);
}
