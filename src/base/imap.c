/* An open-addressing map from 64-bit keys to int32 values. */
#include "base/imap.h"

#include <stdlib.h>
#include <string.h>

#include "base/error.h"

uint64_t fs_mix64(uint64_t x)
{
    x ^= x >> 30;
    x *= UINT64_C(0xbf58476d1ce4e5b9);
    x ^= x >> 27;
    x *= UINT64_C(0x94d049bb133111eb);
    x ^= x >> 31;
    return x == UINT64_MAX ? UINT64_MAX - 1 : x;
}

void fs_imap_init(fs_imap *m, size_t expect)
{
    m->cap = 64;
    while (m->cap < 2 * expect + 16)
        m->cap *= 2;
    m->n = 0;
    m->slot = fs_malloc(m->cap * sizeof *m->slot);
    for (size_t i = 0; i < m->cap; i++)
        m->slot[i].key = UINT64_MAX;
}

void fs_imap_free(fs_imap *m)
{
    free(m->slot);
    memset(m, 0, sizeof *m);
}

static size_t imap_index(const fs_imap *m, uint64_t key)
{
    size_t i = (size_t)fs_mix64(key) & (m->cap - 1);
    while (m->slot[i].key != UINT64_MAX && m->slot[i].key != key)
        i = (i + 1) & (m->cap - 1);
    return i;
}

int32_t *fs_imap_find(const fs_imap *m, uint64_t key)
{
    size_t i = imap_index(m, key);
    return m->slot[i].key == key ? &m->slot[i].val : NULL;
}

int32_t *fs_imap_get(fs_imap *m, uint64_t key, int32_t fresh, bool *found)
{
    if (2 * (m->n + 1) > m->cap) {
        fs_imap old = *m;
        fs_imap_init(m, old.cap);
        for (size_t i = 0; i < old.cap; i++)
            if (old.slot[i].key != UINT64_MAX) {
                m->slot[imap_index(m, old.slot[i].key)] = old.slot[i];
                m->n++;
            }
        fs_imap_free(&old);
    }
    size_t i = imap_index(m, key);
    *found = m->slot[i].key == key;
    if (!*found) {
        m->slot[i].key = key;
        m->slot[i].val = fresh;
        m->n++;
    }
    return &m->slot[i].val;
}
