/* Tests of the growable-array helpers: capacities double from the first size, arrays that share a
 * capacity grow together and keep their elements. */
#include <stdint.h>
#include <stdlib.h>

#include "base/array.h"
#include "check.h"

static void test_array_capacity(void)
{
    CHECK(fs_array_capacity(0, 1, 16) == 16);
    CHECK(fs_array_capacity(0, 16, 16) == 16);
    CHECK(fs_array_capacity(0, 17, 16) == 32);
    CHECK(fs_array_capacity(16, 17, 4) == 32);    /* doubles from cap, not from first */
    CHECK(fs_array_capacity(10, 100, 16) == 160); /* 10 -> 20 -> 40 -> 80 -> 160 */
    CHECK(fs_array_capacity(40, 30, 16) == 40);   /* already large enough: unchanged */
    CHECK(fs_array_capacity(0, 0, 8) == 8);
    /* an int32_t capacity never overflows: clamped at INT32_MAX while need fits */
    CHECK(fs_array_capacity((size_t)1 << 30, ((size_t)1 << 30) + 1, 8) == INT32_MAX);
    /* size_t capacities may pass it when need does */
    CHECK(fs_array_capacity((size_t)1 << 31, ((size_t)1 << 31) + 1, 8) == (size_t)1 << 32);
}

/* Appends one at a time: the capacity goes through first, 2 first, 4 first, ... and the realloc
 * count is logarithmic; every element survives the moves. */
static void test_array_reserve_appends(void)
{
    int32_t *v = NULL, cap = 0, n = 0, grows = 0, last_cap = 0;
    for (int32_t i = 0; i < 1000; i++) {
        FS_ARRAY_RESERVE(v, cap, n + 1, 8);
        if (cap != last_cap) {
            grows++;
            CHECK(last_cap == 0 ? cap == 8 : cap == 2 * last_cap);
            last_cap = cap;
        }
        v[n++] = 3 * i + 1;
    }
    CHECK(cap == 1024 && grows == 8); /* 8, 16, ..., 1024 */
    int32_t bad = 0;
    for (int32_t i = 0; i < n; i++)
        bad += v[i] != 3 * i + 1;
    CHECK(bad == 0);
    free(v);
}

/* Several arrays with one capacity, some of them several entries per item. */
static void test_array_grow_shared(void)
{
    double *xy = NULL;
    uint8_t *flag = NULL;
    size_t cap = 0;
    int32_t n = 0, grows = 0;
    for (int32_t i = 0; i < 300; i++) {
        if (FS_ARRAY_GROW(cap, n + 1, 4)) {
            FS_ARRAY_RESIZE(xy, 2 * cap);
            FS_ARRAY_RESIZE(flag, cap);
            grows++;
        }
        CHECK(cap >= (size_t)n + 1);
        xy[2 * n] = i;
        xy[2 * n + 1] = -i;
        flag[n++] = (uint8_t)(i & 1);
    }
    CHECK(cap == 512 && grows == 8); /* 4, 8, ..., 512 */
    CHECK(!FS_ARRAY_GROW(cap, 512, 4)); /* no growth needed: 0, cap unchanged */
    CHECK(cap == 512);
    int32_t bad = 0;
    for (int32_t i = 0; i < n; i++)
        bad += xy[2 * i] != i || xy[2 * i + 1] != -i || flag[i] != (i & 1);
    CHECK(bad == 0);
    free(xy);
    free(flag);
}

int main(void)
{
    RUN(test_array_capacity);
    RUN(test_array_reserve_appends);
    RUN(test_array_grow_shared);
    return check_finish();
}
