/* An open-addressing map from 64-bit keys to int32 values: welding and edge tables, index sets. */
#ifndef FS_BASE_IMAP_H
#define FS_BASE_IMAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* design: linear probing in a power-of-two table kept at most half full (it doubles before an insert
 * would pass that); keys are mixed (fs_mix64) before they pick a slot, so sequential indices and
 * packed pairs spread. UINT64_MAX marks an empty slot and is never a key. Lookups and inserts do
 * not depend on the order of earlier inserts beyond which keys are present, so what a caller reads
 * back is deterministic. */
typedef struct {
    uint64_t key;
    int32_t val;
} fs_imap_slot;

typedef struct {
    fs_imap_slot *slot;
    size_t cap, n; /* cap is a power of two */
} fs_imap;

/* A 64-bit mix (splitmix64's finaliser), never UINT64_MAX. */
uint64_t fs_mix64(uint64_t x);

/* An empty map with room for about expect keys before it grows. */
void fs_imap_init(fs_imap *m, size_t expect);
void fs_imap_free(fs_imap *m);

/* The value of key, or NULL if it is absent. */
int32_t *fs_imap_find(const fs_imap *m, uint64_t key);

/* The value slot of key; a missing key is inserted with value `fresh` and *found set false. The
 * pointer is valid until the next insert. */
int32_t *fs_imap_get(fs_imap *m, uint64_t key, int32_t fresh, bool *found);

#endif
