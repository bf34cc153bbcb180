/* Tests of the index-list sorting: order, repeats dropped, edge cases, against a brute-force count. */
#include <stdint.h>

#include "base/rng.h"
#include "base/sort.h"
#include "check.h"

static void test_sort_unique_random(void)
{
    enum { N = 2000, RANGE = 300 };
    static int32_t v[N];
    static int count[RANGE];
    for (int i = 0; i < N; i++) {
        v[i] = (int32_t)(fs_rand01(3, FS_RNG_TEST, (uint64_t)i) * RANGE) - RANGE / 2;
        count[v[i] + RANGE / 2]++;
    }
    int32_t n = fs_sort_unique_int32(v, N);
    int distinct = 0;
    for (int k = 0; k < RANGE; k++)
        distinct += count[k] > 0;
    CHECK(n == distinct);
    for (int32_t q = 0; q < n; q++) {
        CHECK(count[v[q] + RANGE / 2] > 0);
        if (q > 0)
            CHECK(v[q - 1] < v[q]);
    }
}

static void test_sort_keeps_repeats(void)
{
    int32_t v[] = {5, -1, 5, INT32_MAX, INT32_MIN, 0, 5};
    fs_sort_int32(v, 7);
    const int32_t want[] = {INT32_MIN, -1, 0, 5, 5, 5, INT32_MAX};
    for (int k = 0; k < 7; k++)
        CHECK(v[k] == want[k]);
    CHECK(fs_sort_unique_int32(v, 7) == 5);
    CHECK(v[3] == 5 && v[4] == INT32_MAX);
    int32_t one = 9;
    CHECK(fs_sort_unique_int32(&one, 1) == 1 && one == 9);
    CHECK(fs_sort_unique_int32(NULL, 0) == 0);
}

int main(void)
{
    RUN(test_sort_unique_random);
    RUN(test_sort_keeps_repeats);
    return check_finish();
}
