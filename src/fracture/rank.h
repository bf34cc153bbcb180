/* Fracture candidate ranking: the largest stress/threshold ratio, ties broken by the seed. */
#ifndef FS_FRACTURE_RANK_H
#define FS_FRACTURE_RANK_H

#include <stdint.h>

/* Two ratios tie when they differ by at most this fraction of the largest ratio. */
#define FS_RANK_TIE_REL 1e-12

/* design: thesis §5.6.2: when the time step cannot be reduced further and several candidates exceed
 * their thresholds, the one with the highest ratio of stress to threshold breaks first; "in case of
 * a tie, one of the candidates is selected randomly". Here "randomly" is a counter-based hash, so the
 * choice depends on (seed, candidate ids) only, never on the order the candidates are listed in.
 *
 * Picks the candidate with the largest ratio (stress/threshold or stretch/threshold; > 1 means over
 * the threshold). Every candidate whose ratio is within FS_RANK_TIE_REL * |max| of the maximum ties;
 * among those the one with the smallest fs_hash3(seed, FS_RNG_TIEBREAK, id) wins, then the smallest
 * id. ids: stable identities of the candidates (element index, or element * points + point), or NULL
 * to use the array index as the id (then the choice does depend on the order). Ids should be
 * distinct; with duplicated ids the first listed of equal (hash, id) wins.
 * NaN ratios are never picked. Returns the array index of the chosen candidate, or -1 if n <= 0 or
 * every ratio is NaN. */
int32_t fs_rank_pick(const double *ratio, const uint64_t *id, int32_t n, uint64_t seed);

/* Number of candidates over their threshold (ratio > 1; NaN never counts). 0 if n <= 0. */
int32_t fs_rank_count_over(const double *ratio, int32_t n);

#endif
