/* Fracture candidate ranking: the largest ratio, with seeded order-independent tie-breaking. */
#include "fracture/rank.h"

#include <math.h>

#include "base/rng.h"

int32_t fs_rank_pick(const double *ratio, const uint64_t *id, int32_t n, uint64_t seed)
{
    double max = -INFINITY;
    int32_t any = 0;
    for (int32_t i = 0; i < n; i++) {
        if (isnan(ratio[i]))
            continue;
        any = 1;
        if (ratio[i] > max)
            max = ratio[i];
    }
    if (!any)
        return -1;
    /* Ties are judged against the maximum, not pairwise, so the tied set does not depend on order. */
    double tie_floor = isinf(max) ? max : max - FS_RANK_TIE_REL * fabs(max);
    int32_t best = -1;
    uint64_t best_hash = 0, best_id = 0;
    for (int32_t i = 0; i < n; i++) {
        if (isnan(ratio[i]) || ratio[i] < tie_floor)
            continue;
        uint64_t key = id ? id[i] : (uint64_t)i;
        uint64_t h = fs_hash3(seed, FS_RNG_TIEBREAK, key);
        if (best < 0 || h < best_hash || (h == best_hash && key < best_id)) {
            best = i;
            best_hash = h;
            best_id = key;
        }
    }
    return best;
}

int32_t fs_rank_count_over(const double *ratio, int32_t n)
{
    int32_t count = 0;
    for (int32_t i = 0; i < n; i++)
        count += ratio[i] > 1.0;
    return count;
}
