/* Inside the springs model (thesis ch. 4): the spring network, the model's state, and what its files and white-box tests share. */
#ifndef FS_MODEL_SPRINGS_INTERNAL_H
#define FS_MODEL_SPRINGS_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "field/field.h"
#include "field/growth.h"
#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/model.h"
#include "solve/sparse.h"

/* ==== Conventions ====
 *
 * Units: lengths in cm, Young's modulus E in MPa (converted to N/cm^2 inside: 1 MPa = 100 N/cm^2),
 * stiffnesses in N/cm, forces in N, energies in N cm, time in the preset's time unit.
 *
 * Masses (thesis §4.1, §4.4): one per node of the Delaunay mesh and per material layer; mass i of
 * layer l is network node l * n + i (n mesh nodes, layer 0 at the bottom). The unknowns are the
 * world positions of the masses at the current time: on the plane and the cylinder the 2-D
 * unwrapped coordinates (x, y) = (s, z) of geom/domain.h (no z component: dim 2), on the sphere
 * points of space (dim 3). Positions are never wrapped; a spring that crosses a periodic seam carries
 * the image offset J(t) (shift_x period_x, shift_y period_y) of its mesh edge, J the background's
 * growth Jacobian, so the network wraps and stays periodic while the background grows.
 *
 * Material springs, one per Delaunay edge and layer. With w the length of the dual Voronoi edge,
 * l0 the edge's length at t = 0 and h the layer thickness:
 *   stiffness   k = (3/2) E h w / l0
 *     design: the thesis (after Hirota et al.) makes k proportional to w / l0; the factor 3/2 makes a
 *     regular triangular lattice (w = l0 / sqrt 3) have the in-plane Young's modulus E h of the layer
 *     (a triangular lattice of springs k has 2-D modulus 2 k / sqrt 3 and Poisson's ratio 1/3, so
 *     material.poisson is not represented; this is one of the model's known limits, thesis §4.7).
 *   rest length L(t) = (1 - s_l(t)) l0, s_l the shrinkage at the layer's mid-height: the bottom and
 *     top functions of [shrink] interpolated linearly through the thickness (thesis Eq. 3.6
 *     generalised to a shrinkage that varies with depth).
 *   breaking: a spring breaks when its strain l / L - 1 exceeds its break strain
 *     eps_b = (threshold / young) * g_t / g_E * (1 + jitter (2 U - 1))
 *     with threshold in kPa and young in MPa (so the first factor is threshold / (1000 young)),
 *     g_t, g_E the grey levels of threshold_map and young_map at the spring's midpoint (white = 1,
 *     floored at 0.01) and U uniform in [0, 1) from (seed, FS_RNG_JITTER, spring). This is the
 *     threshold stress read as a stress on a linear material: strain past threshold / E.
 *     The ratio of a spring is strain / eps_b; > 1 means over its threshold.
 * Anchor springs (thesis §4.1): zero rest length, from each bottom-layer mass to its anchor point
 * on the background, stiffness kappa A, A the mass's Voronoi cell area and
 *   kappa = E / (shear_lag^2 H)     (N/cm^3 per unit area), H the total thickness,
 * so that lambda = shear_lag H = sqrt(E H / kappa) is the shear-lag length over which a free edge
 * relaxes the layer (the 2-D analogue of lambda in model/springs1d.h): crack spacing scales with it.
 * An anchor longer than slide_length slides (thesis: kinetic friction): its force stays
 * kappa A slide_length along the anchor, and when the state is accepted its anchor point moves
 * towards the mass until it is slide_length long.
 * Growth (thesis §4.2): anchor points move with the background, p(t) = fs_growth_flow(p(0), 0, t).
 * Inter-layer springs (thesis §4.3): zero in-plane rest length, joining mass i of layer l to mass i
 * of layer l - 1, stiffness G A / h_l with G = E / (2 (1 + nu)) (shear of a column of the layer
 * between the two mid-planes); they never break.
 * Thickness: H(t) = fs_material_thickness, times thickness_map's grey level at the mass; each
 * layer is H / layers thick.
 *
 * design: quasi-static equilibrium of the geometrically nonlinear network is a minimum of its
 * energy, reached when the largest force left on a mass is below residual * force_scale.
 * fs_spring_net_relax minimises it by inexact Newton: the tangent K at the current state, solved by
 * conjugate gradients preconditioned with the sparse Cholesky factor M (CHOLMOD) of an earlier
 * tangent, an energy line search, and a refactorization (same pattern: analysed once) when the stale
 * factor has cost as many extra iterations as a factorization costs. The tangent of a spring is
 * k (n n^T + max(0, 1 - L / l) (I - n n^T)), positive semi-definite; a slid anchor uses
 * k (slide / d) I. When a spring breaks its stiffness is set to 0 (the pattern stays) and its block is
 * removed from the factor by a rank-dim downdate, so M stays exact for the topology; one step of M
 * then gives the network's linear response to the cut, and what is left out of balance is small and
 * near the cut, relaxed by local conjugate gradients (fs_spring_net_relax_auto).
 *
 * design: fracture in time (thesis §4.1 with §5.6.2, Algorithm 5). From an accepted equilibrium
 * with every ratio <= 1, the time of the next break is predicted from the rates of the ratios (an
 * equilibrium a little later), the state is advanced (accepted) to just before it, and
 * fs_event_find brackets and bisects the crossing to min_step; each evaluation restarts from the
 * accepted state moved along the equilibrium velocity, so it needs few Newton steps. At the event
 * the spring with the largest ratio breaks (fs_rank_pick, the spring index as id, ties by seed),
 * the network re-equilibrates at the same time, and the next over-threshold spring breaks, until
 * none is over; then time advances again. */

/* ==== The generic spring network and its relaxation ==== */

/* Point masses joined by springs and anchored by zero-rest-length springs to points. The caller
 * fills the topology and the values; fs_spring_net_prepare fixes the sparse pattern; values
 * (positions, rest lengths, stiffnesses, anchor points) may then change freely between relaxations,
 * the topology may not. Every array is owned by the struct. */
typedef struct {
    int dim;                 /* 2 or 3: coordinates per node */
    int32_t n_nodes;
    double *x;               /* dim * n_nodes positions (cm) */
    uint8_t *fixed;          /* n_nodes: 1 = the position is prescribed (not an unknown) */

    int32_t n_springs;
    int32_t *node;           /* 2 * n_springs: ends a, b (distinct) */
    double *offset;          /* dim * n_springs: added to x[b] (periodic image), usually 0 */
    double *rest;            /* n_springs: rest length (cm); 0 = zero-rest-length spring */
    double *k;               /* n_springs: stiffness (N/cm); 0 = no force (a broken spring) */

    int32_t n_anchors;
    int32_t *anchor_node;    /* n_anchors: the node each anchor holds */
    double *anchor_at;       /* dim * n_anchors: anchor point (cm) */
    double *anchor_k;        /* n_anchors: stiffness (N/cm) */
    double slide;            /* anchor length (cm) past which anchors slide; <= 0 never */

    /* solver state, owned, built by fs_spring_net_prepare */
    int32_t n_dof;
    int32_t *dof;            /* n_nodes: first unknown of the node, or -1 if fixed */
    fs_sparse_matrix K;      /* tangent stiffness, upper triangle, fixed pattern */
    int32_t *node_slot;      /* n_nodes: entry number of the node's first diagonal-block entry (its
                                dim (dim + 1) / 2 upper entries follow), or -1 if fixed */
    int32_t *spring_slot;    /* n_springs: entry number of its first off-diagonal entry (dim * dim
                                follow, row-major a x b), or -1 unless both ends are free */
    int32_t *slots;          /* entry number -> index into K.values */
    fs_cholesky *chol;
    bool factor_valid;       /* chol holds the factor of the tangent at fact_x (minus downdates) */
    double *fact_x;          /* positions, */
    double *fact_rest;       /* rest lengths, */
    double *fact_k;          /* stiffnesses */
    double *fact_offset;     /* and offsets the factor was computed with (for exact downdates) */
    double *work;            /* scratch: 7 * (n_dof + 1) + dim * n_nodes */
    int32_t *adj_start;      /* n_nodes + 1: CSR node -> incident springs */
    int32_t *adj_spring;
    int32_t *anc_start;      /* n_nodes + 1: CSR node -> its anchors */
    int32_t *anc_list;
    int32_t *local_map;      /* n_nodes: index in the current local region, or -1 */
    double *local_dist;      /* n_nodes: hops from the region's seeds while it grows (geom/region.h),
                                INFINITY between growths */
    int32_t local_radius;    /* first graph radius (hops) of a local relaxation; <= 0 means 6 */
    double screening;        /* hops over which a local disturbance decays by e (<= 0: 3) */
    int32_t *seeds;          /* n_nodes scratch: nodes out of balance */
    double factor_cost;      /* a numeric factorization's price in solves (CHOLMOD's flop counts) */
    double stale_solves;     /* conjugate-gradient solves spent since the last factorization beyond one per step */
    int64_t factorizations;  /* counters for logs and benchmarks */
    int64_t solves;
} fs_spring_net;

/* What one relaxation did. */
typedef struct {
    int iterations;          /* Newton steps */
    int factorizations;      /* numeric factorizations among them */
    double energy_start;     /* energy before (N cm) */
    double energy_end;       /* energy after */
    bool energy_monotone;    /* every accepted step lowered the energy (or kept it within rounding) */
    double residual_start;   /* largest force imbalance on a node before (N) */
    double residual_end;     /* and after: <= the tolerance on success */
} fs_spring_relax_info;

/* Allocates a network with zeroed arrays (all nodes free, offsets 0, slide 0). Free with
 * fs_spring_net_free. dim must be 2 or 3 (FS_ASSERT). */
void fs_spring_net_init(fs_spring_net *net, int dim, int32_t n_nodes, int32_t n_springs, int32_t n_anchors);
void fs_spring_net_free(fs_spring_net *net);

/* Numbers the unknowns, builds the tangent's sparse pattern with its slots and analyses it.
 * Springs with both ends fixed or with a == b (FS_ASSERT: never) contribute nothing to the pattern.
 * Returns 0, or -1 with fs_error (FS_ERR_INTERNAL from CHOLMOD). */
int fs_spring_net_prepare(fs_spring_net *net);

/* Total elastic energy (N cm) at the current positions: sum of k (l - L)^2 / 2 over springs and of
 * the anchors' energy (k d^2 / 2, continued linearly past the sliding length). */
double fs_spring_net_energy(const fs_spring_net *net);

/* Net force on every free node (force = minus the energy gradient), written to f (n_dof entries,
 * may be NULL). Returns the largest Euclidean norm of a node's force (N). */
double fs_spring_net_force(const fs_spring_net *net, double *f);

/* Relaxes the free nodes to equilibrium: the largest node force ends <= tolerance (N). Requires
 * fs_spring_net_prepare. info may be NULL. Returns 0, or -1 with fs_error(FS_ERR_INTERNAL,
 * "springs: no equilibrium after N steps (residual r N, tolerance t N)") or a CHOLMOD failure;
 * positions are then finite but not in equilibrium. */
int fs_spring_net_relax(fs_spring_net *net, double tolerance, int max_iterations, fs_spring_relax_info *info);

/* One step p = M^-1 f with the current factor (made if there is none) and a
 * backtracking line search; *residual receives the largest node force afterwards. Returns 1 if a
 * step was taken, 0 if none lowered the energy, -1 with fs_error on a solver failure. */
int fs_spring_net_step(fs_spring_net *net, double *residual);

/* Relaxes after a local disturbance (a spring cut) around the nodes seeds[0..n_seeds-1], starting
 * from an equilibrium with every node force <= tolerance: Newton steps solved by block-Jacobi
 * preconditioned conjugate gradients on the nodes within a graph radius of the seeds (the others
 * held), the radius doubling until the forces on the nodes just outside the region are within the
 * tolerance too; so on success every node's force is <= tolerance, as after fs_spring_net_relax.
 * design: an anchored layer screens a disturbance over its shear-lag length, so the region stays
 * small and the cost does not grow with the network; a region past a third of the nodes falls back
 * to fs_spring_net_relax. Returns 0 or -1 with fs_error(FS_ERR_INTERNAL). */
int fs_spring_net_relax_local(fs_spring_net *net, const int32_t *seeds, int32_t n_seeds, double tolerance,
                              fs_spring_relax_info *info);

/* Relaxes from the current positions by the cheapest route: nothing when every node force is within
 * the tolerance; after a large imbalance (a cut spring) one step of the factor first, which
 * holds the topology exactly (when the imbalance would reach over a ninth of the nodes, judged from
 * `screening`); then fs_spring_net_relax_local around the nodes still out of balance
 * when they are few (at most a sixteenth of the nodes), fs_spring_net_relax otherwise. Returns 0 or
 * -1 as those. */
int fs_spring_net_relax_auto(fs_spring_net *net, double tolerance, fs_spring_relax_info *info);

/* Breaks spring s: its stiffness becomes 0 and its block is downdated out of the current factor
 * (a failed downdate only invalidates the factor; the next relaxation refactorizes). */
void fs_spring_net_cut(fs_spring_net *net, int32_t s);

/* ==== The springs model ==== */


/* One break. */
typedef struct {
    int32_t spring;          /* material spring index (layer * n_edges + edge) */
    double time;
    double ratio;            /* its strain / break strain when it broke (> 1) */
} fs_springs_break;

/* The model's state. The mesh is borrowed and must outlive the state. Flat arrays, owned. */
struct fs_springs {
    fs_model_setup setup;
    const fs_mesh *mesh;
    fs_voronoi vor;          /* the mesh's Voronoi dual (cell areas, dual edge lengths, circumcentres) */
    fs_growth_field growth;
    int dim;                 /* 2 (plane, cylinder) or 3 (sphere) */
    int32_t n;               /* masses per layer = mesh nodes */
    int layers;
    double ext[2];           /* periods of the unwrapped rectangle (plane, cylinder; 0 on non-wrapping axes) */

    fs_spring_net net;       /* material springs first (index layer * n_edges + edge, inert on a
                                periodic self-edge), then the inter-layer springs */
    int32_t n_edges;
    int32_t n_material;      /* layers * n_edges */
    double *rest0;           /* n_material: l0, the reference length (cm) */
    double *coef;            /* n_material: k / H(t), i.e. (3/2) E w / l0 * grey levels / layers (N/cm^2) */
    double *ref_offset;      /* dim * n_material: reference image offset of the edge (cm) */
    double *break_strain;    /* n_material: eps_b, 0 for inert springs */
    uint8_t *broken;         /* n_material: 1 once broken (or inert) */
    double *ratio;           /* n_material: strain / eps_b at the current state; NaN when broken */
    double *inter_coef;      /* n: stiffness * H(t) of mass i's inter-layer springs (N) */
    double *anchor_coef;     /* n: stiffness * H(t) of mass i's anchor (N) */
    double *anchor_ref;      /* dim * n: anchor points in background coordinates at t = 0 (cm) */
    double *thick;           /* n: thickness_map grey level of each mass (1 without a map) */
    double force_scale;      /* force of a median spring at its break strain (N): residual unit */

    double time;             /* time of the accepted state */
    double *x_accepted;      /* dim * n * layers: accepted positions */
    double *velocity;        /* dim * n * layers: d position / dt of the equilibrium at the accepted state
                                (in its frame, background motion removed); starts the next relaxations */
    double *anchor_accepted; /* dim * n: accepted anchor_ref */
    double *rate;            /* n_material: scratch for the event prediction */
    double state_time;       /* time the net currently holds (may differ from `time` during a search) */

    fs_springs_break *breaks;
    int32_t break_count, break_capacity;
    int64_t evaluations;     /* equilibrium solves by the event search */
    int64_t relax_steps;     /* Newton steps, all relaxations */
};

/* Builds the network on mesh m (edges, rings built; the mesh's domain decides dim and wrapping),
 * at time 0, not yet relaxed. Reads the grey-level maps of setup->material. Returns 0, or -1 with
 * fs_error: FS_ERR_DATA for bad parameters (naming the [springs] key), a growth that does not suit the
 * domain or a mesh too small; FS_ERR_NOINPUT/FS_ERR_DATA for an unreadable map. *s needs
 * fs_springs_free either way. */
int fs_springs_init(fs_springs *s, const fs_mesh *m, const fs_model_setup *setup);
void fs_springs_free(fs_springs *s);

/* Brings a copy of the accepted state to time t (anchors and positions moved with the background,
 * positions also along the last equilibrium velocity, rest lengths and stiffnesses at t) and relaxes
 * it, without breaking or accepting anything.
 * Returns the largest ratio over intact springs (-INFINITY if none), or NaN with fs_error. This is
 * the fs_event_fn of the search. */
double fs_springs_equilibrate(fs_springs *s, double t);

/* Accepts the current state (after fs_springs_equilibrate or a break): slid anchors move. */
void fs_springs_accept(fs_springs *s);

/* Reference direction (unit, domain coordinates, unwrapped across seams) of material spring i. */
void fs_springs_direction(const fs_springs *s, int32_t spring, double dir[3]);

/* Fragments: connected components of the masses of the top layer through its intact springs.
 * label (n entries) receives for each mass the smallest mass index of its fragment. Returns the
 * number of fragments. */
int32_t fs_springs_fragments(const fs_springs *s, int32_t *label);


#endif
