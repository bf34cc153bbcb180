/* Tests of the open-addressing map: every key inserted is found with its first value, absent keys
 * are not, across the table's growth; packed pairs and sequential indices alike. */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>

#include "base/imap.h"
#include "check.h"

enum { N = 5000 };

/* The key of item k: sequential indices for the first half, packed pairs of indices after. */
static uint64_t key_of(int32_t k)
{
    return k < N / 2 ? (uint64_t)k : (uint64_t)(uint32_t)(k % 97) << 32 | (uint32_t)k;
}

static void test_imap_insert_find(void)
{
    fs_imap m;
    fs_imap_init(&m, 4); /* grows many times */
    int inserted = 0, repeated = 0;
    for (int32_t k = 0; k < N; k++) {
        bool found;
        int32_t *v = fs_imap_get(&m, key_of(k), k, &found);
        inserted += !found && *v == k;
        /* a second insert of the same key finds it and keeps the first value */
        v = fs_imap_get(&m, key_of(k), -5, &found);
        repeated += found && *v == k;
    }
    CHECK(inserted == N && repeated == N);
    CHECK(m.n == N && m.cap >= 2 * (size_t)N && (m.cap & (m.cap - 1)) == 0);
    int ok = 0;
    for (int32_t k = 0; k < N; k++) {
        const int32_t *v = fs_imap_find(&m, key_of(k));
        ok += v && *v == k;
    }
    CHECK(ok == N);
    int absent = 0;
    for (int32_t k = N; k < 2 * N; k++)
        absent += fs_imap_find(&m, (uint64_t)k + ((uint64_t)1 << 40)) == NULL;
    CHECK(absent == N);
    fs_imap_free(&m);
    CHECK(m.slot == NULL && m.n == 0);
}

static void test_mix64(void)
{
    CHECK(fs_mix64(0) != UINT64_MAX);
    /* sequential keys spread over the low bits that pick a slot */
    int used[64] = {0}, distinct = 0;
    for (uint64_t k = 0; k < 64; k++)
        used[fs_mix64(k) & 63] = 1;
    for (int i = 0; i < 64; i++)
        distinct += used[i];
    CHECK_MSG(distinct >= 32, "64 sequential keys fill only %d of 64 slots", distinct);
}

int main(void)
{
    RUN(test_imap_insert_find);
    RUN(test_mix64);
    return check_finish();
}
