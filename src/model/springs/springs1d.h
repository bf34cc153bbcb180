/* The 1-D mass-spring model of thesis Appendix A: a chain on a stretching background, and its analytic twin. */
#ifndef FS_MODEL_SPRINGS1D_H
#define FS_MODEL_SPRINGS1D_H

#include <stdint.h>

/* Conventions (thesis Appendix A).
 *
 * The bar occupies the reference (material) coordinates x in [0, L]. The background stretches
 * uniformly about x = 0: the anchor point of material point x is at a(x, t) = x (1 + rate t), so the
 * background strain is eps_b(t) = rate t. The material has no rest-length change (no shrinkage).
 * Units: lengths in cm, forces in N, time in the unit of the strain rate (1/time); strains are
 * dimensionless. EA (N) is the force per unit strain of the bar, so a material spring of rest length h
 * has stiffness EA / h (N/cm); k (N/cm^2) is the foundation (anchor) stiffness per unit length of bar,
 * so the anchor of a piece of length h has stiffness k h (N/cm). lambda = sqrt(EA / k) (cm) is the
 * shear-lag length: the distance over which a free end relaxes the material.
 *
 * Discrete chain (thesis §A.1, Fig. A.1): n masses at x_i = i h, h = L / (n - 1), joined by n - 1
 * material springs; spring j joins masses j and j + 1 and its crack, once broken, sits at its
 * midpoint x_j + h / 2. Mass i is anchored by a zero-rest-length spring to a(x_i, t) with stiffness
 * k h for interior masses and k h / 2 for the two end masses (each spring's anchor is split between its
 * two endpoints, thesis Eq. A.7-A.8). A spring breaks when its strain (length / h - 1) exceeds its
 * threshold; a broken spring carries nothing (thesis: "setting the stiffness coefficient of the broken
 * spring to zero"); masses keep their anchors.
 * The thesis' formulas are scrambled in our copy: the k h / 2 end anchors are read from Eq. A.7-A.8
 * (and are what makes the chain converge to the free-end continuum at second order); the continuous
 * solution below was re-derived from the mechanics and agrees with the legible parts of Eq. A.4-A.6
 * and A.11 (tests/test_springs1d.c checks the Eq. A.6/A.11 form against it). */

typedef struct {
    double length;             /* L (cm): rest length of the bar; > 0 */
    double material_stiffness; /* EA (N): force per unit strain of the bar; > 0 */
    double anchor_stiffness;   /* k (N/cm^2): foundation stiffness per unit length; > 0 */
    double strain_rate;        /* background strain per unit time (1/time); finite, <= 0 never cracks */
    double threshold_strain;   /* breaking strain of the material springs; > 0 (force: EA times it) */
    double jitter;             /* per-spring threshold factor uniform in [1 - jitter, 1 + jitter);
                                  0 <= jitter < 1; 0 makes the thresholds uniform */
    int32_t masses;            /* n >= 2: the discretisation */
    uint64_t seed;             /* threshold jitter and ranking ties */
    double min_step;           /* time resolution of the fracture event search (> 0): a break time
                                  is at most this late */
} fs_springs1d_params;

/* L = 10 cm, EA = 1 N, k = 1 N/cm^2 (lambda = 1 cm), rate 1, threshold strain 0.01, no jitter,
 * n = 101 masses, seed 1, min_step 1e-12. */
fs_springs1d_params fs_springs1d_params_default(void);

/* One crack: when and where it opened. */
typedef struct {
    double time;    /* time of the break */
    double x;       /* reference coordinate of the crack (cm), in [0, L] */
    int32_t spring; /* discrete chain: the broken spring's index; analytic cracks: -1 */
} fs_springs1d_break;

/* The chain's state. Flat arrays indexed by mass (n) or spring (n - 1), owned by the struct. */
typedef struct {
    fs_springs1d_params params;
    int32_t masses;            /* n */
    double spacing;            /* h = L / (n - 1) (cm) */
    double time;               /* the time the current equilibrium belongs to */
    double *slip;              /* n: position minus anchor point (cm), the anchor spring's extension;
                                  the solver's unknowns (position = x_i (1 + rate time) + slip) */
    double *threshold;         /* n - 1: breaking strain of each spring (jittered) */
    uint8_t *broken;           /* n - 1: 1 once the spring has broken */
    double *ratio;             /* n - 1: strain / threshold at `time`; NaN for broken springs */
    fs_springs1d_break *breaks;/* the breaks so far, in the order they happened */
    int32_t break_count;
    int32_t break_capacity;
    double *scratch;           /* 2n: Thomas algorithm workspace */
} fs_springs1d;

/* Validates p and builds an intact chain in equilibrium at time 0 (slip 0). Returns 0, or -1 with
 * fs_error(FS_ERR_DATA) naming the bad parameter (then *s is zeroed and needs no free). */
int fs_springs1d_init(fs_springs1d *s, const fs_springs1d_params *p);

/* Releases the arrays; *s is zeroed. Safe on a zeroed struct. */
void fs_springs1d_free(fs_springs1d *s);

/* Brings the chain to time t (any finite t, earlier or later) and solves its equilibrium exactly
 * (tridiagonal, Thomas algorithm; the 1-D model is linear between breaks), filling slip and ratio.
 * Breaks nothing. Returns the largest ratio over the intact springs (-INFINITY if none is intact), or
 * NaN with fs_error(FS_ERR_DATA) for a non-finite t. */
double fs_springs1d_equilibrate(fs_springs1d *s, double t);

/* Strain of spring j in the current equilibrium (length / h - 1); 0 for a broken spring. */
double fs_springs1d_spring_strain(const fs_springs1d *s, int32_t j);

/* Current position (cm) of mass i. */
double fs_springs1d_position(const fs_springs1d *s, int32_t i);

/* design: thesis §A.1 with the event search of §5.6.2 (Algorithm 5). Advances from s->time to t_end:
 * while some intact spring is over its threshold at the current time, the one with the largest
 * strain/threshold ratio (fs_rank_pick, ties broken by the seed with the spring index as id) breaks
 * and the chain re-equilibrates at the same time (a cascade); otherwise fs_event_find brackets and
 * bisects the next time a ratio passes 1. Every break is appended to s->breaks. Ends equilibrated
 * at t_end (or at the last break time if every spring has broken). Returns 0, or -1 with fs_error
 * (FS_ERR_DATA for t_end < s->time or non-finite). */
int fs_springs1d_run(fs_springs1d *s, double t_end);

/* ---- the analytic continuous solution (thesis §A.2) ---- */

/* lambda = sqrt(EA / k) (cm). */
double fs_springs1d_decay_length(const fs_springs1d_params *p);

/* design: thesis §A.2, Eq. A.4-A.6 and A.11 (boundary condition type I, no neighbours). The
 * continuum limit of the chain is EA u'' = k (u - eps_b x) for the displacement u(x). With the slip
 * w = u - eps_b x this is w'' = w / lambda^2; free ends carry no force, u' = 0, i.e. w' = -eps_b.
 * For a segment of length l with s measured from its centre the symmetric solution is
 * w = -eps_b lambda sinh(s / lambda) / cosh(l / (2 lambda)), so the material strain is
 *     strain(s) = u' = eps_b (1 - cosh(s / lambda) / cosh(l / (2 lambda)))
 * and the force EA strain(s): zero at the ends, largest at the centre. This is the thesis' Eq. A.6 with
 * the constants of Eq. A.11 rewritten about the centre (the test checks the two forms agree).
 * Returns the strain at offset s (|s| <= l / 2) of a free segment of length l under background
 * strain eps_b. */
double fs_springs1d_analytic_strain(double eps_b, double lambda, double l, double s);

/* The time a free segment of length l (cm, > 0) of uniform threshold cracks: the centre strain
 * rate t (1 - 1 / cosh(l / (2 lambda))) reaches threshold_strain, so
 *     t = threshold_strain / (rate (1 - 1 / cosh(l / (2 lambda)))).
 * INFINITY if rate <= 0 or the denominator underflows (very short segments never crack). */
double fs_springs1d_analytic_crack_time(const fs_springs1d_params *p, double l);

/* The first crack of the intact bar: at its centre x = L / 2, at time
 * fs_springs1d_analytic_crack_time(p, L). */
fs_springs1d_break fs_springs1d_analytic_first_crack(const fs_springs1d_params *p);

/* design: once cracked, each piece is again a free segment, so it cracks at its own centre when its
 * own centre strain reaches the threshold; pieces of equal length crack together. With a uniform
 * threshold the cracks form a hierarchy of halving segments: generation g (0-based) has 2^g cracks at
 * x = (2m + 1) L / 2^(g+1), m = 0 .. 2^g - 1, all at time crack_time(L / 2^g), later for each g because
 * shorter segments relax more. Jitter is ignored.
 * Writes the first 2^generations - 1 cracks to out (caller-owned, that many entries), in time order
 * and, within a generation, by position. Returns the count, or -1 with fs_error(FS_ERR_DATA) unless
 * 0 <= generations <= 30. */
int32_t fs_springs1d_analytic_cracks(const fs_springs1d_params *p, int32_t generations, fs_springs1d_break *out);

#endif
