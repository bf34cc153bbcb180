/* Tests of the counter-based random numbers: determinism, independence of streams, distribution. */
#include <stdint.h>

#include "base/rng.h"
#include "check.h"

static void test_deterministic(void)
{
    CHECK(fs_hash3(7, FS_RNG_TEST, 42) == fs_hash3(7, FS_RNG_TEST, 42));
    CHECK(fs_rand01(7, FS_RNG_TEST, 42) == fs_rand01(7, FS_RNG_TEST, 42));
    /* A stored value pins the generator: changing it changes every seeded output. */
    CHECK_MSG(fs_hash3(1, 1, 0) == UINT64_C(0x8f39bda1d3ac9995), "got %016llx", (unsigned long long)fs_hash3(1, 1, 0));
}

static void test_streams_differ(void)
{
    int same_seed = 0, same_purpose = 0, same_index = 0;
    for (uint64_t i = 0; i < 1000; i++) {
        same_seed += fs_hash3(1, FS_RNG_TEST, i) == fs_hash3(2, FS_RNG_TEST, i);
        same_purpose += fs_hash3(1, FS_RNG_TEST, i) == fs_hash3(1, FS_RNG_NOISE, i);
        same_index += fs_hash3(1, FS_RNG_TEST, i) == fs_hash3(1, FS_RNG_TEST, i + 1);
    }
    CHECK(same_seed == 0);
    CHECK(same_purpose == 0);
    CHECK(same_index == 0);
}

static void test_uniform(void)
{
    enum { N = 200000, BINS = 20 };
    int bins[BINS] = {0};
    double sum = 0, lo = 1, hi = 0;
    for (int i = 0; i < N; i++) {
        double u = fs_rand01(3, FS_RNG_TEST, (uint64_t)i);
        CHECK(u >= 0 && u < 1);
        sum += u;
        lo = u < lo ? u : lo;
        hi = u > hi ? u : hi;
        bins[(int)(u * BINS)]++;
    }
    CHECK_NEAR(sum / N, 0.5, 0.005);
    CHECK(lo < 1e-4 && hi > 1 - 1e-4);
    /* Chi-square with 19 degrees of freedom: 43.8 is the 0.1 % critical value. */
    double chi2 = 0, expect = (double)N / BINS;
    for (int b = 0; b < BINS; b++)
        chi2 += (bins[b] - expect) * (bins[b] - expect) / expect;
    CHECK_MSG(chi2 < 43.8, "chi2 = %g", chi2);
}

static void test_normal(void)
{
    enum { N = 100000 };
    double s = 0, s2 = 0;
    for (int i = 0; i < N; i++) {
        double z = fs_rand_normal(5, FS_RNG_TEST, (uint64_t)i);
        s += z;
        s2 += z * z;
    }
    CHECK_NEAR(s / N, 0.0, 0.02);
    CHECK_NEAR(s2 / N, 1.0, 0.02);
}

int main(void)
{
    RUN(test_deterministic);
    RUN(test_streams_differ);
    RUN(test_uniform);
    RUN(test_normal);
    return check_finish();
}
