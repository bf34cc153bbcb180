/* Inside the wedge model (thesis ch. 5): its state, and what its files and white-box tests share. */
#ifndef FS_MODEL_WEDGE_INTERNAL_H
#define FS_MODEL_WEDGE_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "field/growth.h"
#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/model.h"
#include "solve/node_order.h"
#include "solve/sparse.h"

/* design: every triangle of the surface mesh is extruded into one wedge (thesis §5.2): its bottom
 * nodes are attached to the background and fixed, its top nodes are free. Mesh node i carries a
 * bottom node and a top node, so neighbouring wedges share nodes and the layer is conforming.
 *
 * Frames. Plane and cylinder are simulated flat, in the unwrapped rectangle of the domain: x and y
 * are the first two domain coordinates (cm; on the cylinder the arc length around the trunk and the
 * height along it) and z points up, away from the background; wedges that straddle a periodic seam
 * use the mesh's corner shifts, so the one set of nodes wraps and so does the linear system. The
 * cylinder is therefore treated as a thin layer (curvature neglected, h / R small) whose growth
 * around the axis is the equivalent eigenstrain below. The sphere is simulated in 3-D: a top node
 * sits on the outward normal of its bottom node (fs_domain_normal) at the local thickness.
 *
 * Growth (thesis §3.3.1). Non-periodic plane and sphere: the fixed bottom nodes move along the
 * background's flow (fs_growth_flow), which loads the layer through the coupling between fixed and
 * free nodes. Periodic plane and cylinder: moving the nodes would break the periodic identification,
 * so the layer takes the equivalent eigenstrain -(F - I) instead (fs_growth_strain; equal stresses in
 * linear elasticity) and the bottom nodes stay where they are.
 *
 * Shrinkage (thesis §3.3.2, Fig. 3.10): the reference shape of a wedge at time t scales its bottom
 * triangle about the bottom centroid by scale[0], its top triangle about the top centroid by
 * scale[1], and the centroid-to-centroid height by scale[2] (fs_shrink_scales). Linearised (small
 * strain, as everywhere in the model), the element force is K_e (u_e - u0_e) with u0_e the
 * displacement from the original wedge to its reference shape; u0_e is linear in (scale - 1), so the
 * global load is a fixed combination of three load vectors assembled once.
 *
 * So while the mesh does not change, the stiffness matrix does not change either: growth and
 * shrinkage only change the right-hand side, and one Cholesky factor serves every equilibrium.
 * Exception: a thickness that changes over time (thickness_final) changes the geometry, and the
 * system is then re-assembled and re-factored (symbolic analysis kept) whenever the time changes.
 *
 * Units: lengths cm, E in MPa, stresses MPa (the preset's kPa threshold is converted), forces
 * MPa cm^2. Voigt order and stress conventions as in model/wedge/element.h. */

/* Unit load patterns per element: three of shrinkage, three of eigenstrain (see wedge.c). */
#define FS_WEDGE_PATTERNS 6

/* Pairs (a <= c) of an element's 18 DOFs. */
#define FS_WEDGE_PAIRS 171

/* Inputs of an element's stiffness parts (k_parts): its corners' x and y, their thickness factors,
 * its Young's modulus. */
#define FS_WEDGE_K_KEY 10

/* How an element left the model. */
typedef enum { FS_WEDGE_ALIVE = 0, FS_WEDGE_REMOVED = 1 } fs_wedge_state;

/* How background growth loads the layer (see the design note). */
typedef enum { FS_WEDGE_GROWTH_NONE = 0, FS_WEDGE_GROWTH_MOVE, FS_WEDGE_GROWTH_EIGENSTRAIN } fs_wedge_growth_mode;

/* Counters and timings of the solver, for logs and benchmarks. */
typedef struct {
    int64_t solves;           /* equilibrium solves */
    int64_t cg_iterations;    /* summed over CG solves */
    int64_t analyses;         /* symbolic analyses (a new pattern: first assembly, subdivision) */
    int64_t factorizations;   /* numeric factorizations */
    int64_t updowns;          /* rank updates of the factor after an element removal */
    int64_t removals;         /* elements removed (fractures) */
    int64_t subdivisions;     /* elements subdivided instead of removed (Algorithm 8) */
    double assemble_seconds, analyze_seconds, factor_seconds, update_seconds, solve_seconds,
        stress_seconds;
    int64_t local_relaxations; /* fs_wedge_relax calls that ended in equilibrium without a global solve */
    int64_t global_fallbacks;  /* fs_wedge_relax calls that needed a global solve */
    int64_t relax_retries;     /* local relaxations repeated at a doubled radius within one call */
    int64_t local_dofs;        /* unknowns of the local systems, summed over fs_wedge_relax calls */
    int64_t local_cg_iterations; /* CG iterations of the local systems */
    double local_seconds;      /* time in fs_wedge_relax, global fallbacks included */
    int64_t time_steps;        /* event searches (advances of time, Algorithm 5) */
    int64_t search_evaluations; /* their exact and estimated evaluations (fracture/event.h) */
    int64_t event_relaxations; /* returns to equilibrium after a fracture event (fs_wedge_simulate) */
    double event_relax_seconds; /* their time, local or global */
    double event_seconds;      /* the events' whole time: the fracture (the cut, the system's update or
                                  re-factorization) and the relaxation */
    int64_t vm_rounds;         /* rounds of refinement by von Mises discontinuity that bisected (wedge/tips.c) */
    int64_t vm_bisections;     /* their bisections (also counted in subdivisions) */
    double vm_seconds;         /* their time: indicators, subdivision, re-solves */
    int64_t submodels;         /* crack-tip sub-models solved (wedge/tips.c) */
    int64_t submodel_elements; /* their elements after refinement, summed */
    int64_t submodel_rejections; /* picked tips the sub-model found below their threshold */
    double submodel_seconds;   /* their time: extraction, refinement, assembly, solve */
    int64_t smoothings;        /* angle-smoothing passes around new tips (wedge/tips.c) */
    int64_t smoothed_nodes;    /* nodes they moved */
    double smooth_seconds;     /* their time, the system's update included (not the relaxation) */
} fs_wedge_counters;

/* The whole state of one layer. Arrays are flat and indexed by mesh node or mesh triangle (one wedge
 * per triangle); the model owns all of them except the mesh. */
/* The coupling K_fb of the free DOFs with the fixed ones: one column per fixed DOF (its index minus
 * n_free), holding its free rows strictly ascending with their values. A column lives in
 * row[start .. start + len) with room up to start + cap, so a cut adds entries in place; a full column
 * moves to the end of the pool (see fs_wedge_coupling_insert in system.c). Fixed indices and free rows keep
 * their numbers when nodes are added (number_dofs), so no column ever shifts. */
typedef struct {
    int32_t n;                   /* columns (n_fixed) */
    int32_t *start, *len, *cap;  /* per column */
    int32_t *row;                /* free row of each slot */
    double *value;               /* value of each slot */
    size_t used, size;           /* slots handed out (holes left by moved columns included), allocated */
    size_t entries;              /* sum of len */
} fs_wedge_coupling;

struct fs_wedge_model {
    fs_mesh *mesh;               /* borrowed, must outlive the model; subdivision refines it in place */
    fs_model_setup cfg;          /* copy of the setup the model was built from */
    fs_growth_field growth;      /* the resolved background growth */
    fs_wedge_growth_mode growth_mode;
    bool flat;                   /* plane or cylinder (unwrapped frame); false on the sphere */
    double d_unit[36];           /* the elasticity matrix for E = 1 (scaled by each element's E) */
    double time;                 /* time of the current equilibrium */
    double shrink_coef[3];       /* at that time: scale - 1 of the reference shapes (fs_shrink_scales) */
    double eigenstrain[3];       /* at that time: the growth eigenstrain xx, yy, xy (eigenstrain mode) */

    /* Nodes: mesh node i has a bottom node and a top node; "node DOF" 6 i + k is component k of the
     * bottom node (k < 3) or of the top node (k >= 3). */
    int32_t n_nodes;
    int32_t node_cap, elem_cap;  /* nodes and elements the per-node and per-element arrays have room for
                                    (fs_wedge_grow_arrays) */
    double *normal;              /* 3 per node: unit extrusion direction (flat frames: +z) */
    double *thickness_factor;    /* per node: thickness map and gradient factor (times the thickness at t) */
    uint8_t *pinned;             /* per node: 1 if its top node is prescribed too (patch tests), else 0 */
    int32_t *origin;             /* per node: the node a cut copied it from (its nearer parent), -1 if none */
    double *prescribed;          /* 6 per node: prescribed displacement of fixed DOFs besides growth (cm) */
    double *u;                   /* 6 per node: displacement at the current equilibrium (cm) */
    int32_t *node_elem_start;    /* per node: where its list of the elements using it (ascending,
                                    dead ones too) starts in node_elem */
    int32_t *node_elem_count;    /* per node: entries of its list */
    int32_t *node_elem_room;     /* per node: entries its list may grow to in place */
    int32_t node_elem_cap;       /* nodes node_elem_start and node_elem_room have room for */
    int32_t *node_elem;
    int32_t node_elem_used, node_elem_capacity; /* entries of node_elem handed out, allocated */

    /* Elements. */
    int32_t n_elems;
    uint8_t *state;              /* fs_wedge_state per element */
    double *young;               /* per element: Young's modulus (MPa), with the map */
    bool k_parts_on;             /* the layer's thickness changes in time on a flat frame */
    double *k_parts;             /* per element, 3 x FS_WEDGE_PAIRS, with k_parts_on (else NULL): the upper
                                    triangles (row by row) of K1, K0, K2 of its stiffness h K1 + K0 + K2 / h
                                    at base thickness h (fs_wedge_element_system) */
    double *k_key;               /* per element, FS_WEDGE_K_KEY: the inputs k_parts were fitted to */
    int32_t *refill_slot;        /* per element, FS_WEDGE_PAIRS, for fs_wedge_refill_system: where each
                                    kept pair of its DOFs lies (system.c) */
    int32_t refill_slot_elems;   /* elements refill_slot has room for */
    uint64_t pattern_version;    /* bumped whenever the DOF numbering or the system's pattern changes */
    uint64_t refill_slot_version; /* the pattern_version refill_slot was made for (0: none) */
    double *threshold;           /* per element: threshold stress (MPa), with the map and jitter */
    double *ratio;               /* per element, at the current equilibrium: the largest principal
                                    stress at the three top Gauss points over the threshold, or an
                                    upper bound of it; with fracture by removal, exact for the largest
                                    ratio and every ratio that ties with it when that is over 1 (what
                                    removal decides on, see equilibrium.c; splitting decides on nodal
                                    ratios); NaN when not alive. fs_wedge_element_ratio is exact. */
    double *stress_top;          /* 18 per element: Voigt stress (MPa) at the top Gauss points 0..2;
                                    with lazy_ratios, as of the element's last full evaluation */
    double *gauss_cache;         /* 108 per element: geometry terms of the stress check (FS_WEDGE_GAUSS_CACHE) */
    double *edge_rest;           /* 3 per living element: length (cm) of its edge c (corners c and
                                    c + 1) in the surface mesh at rest, set with gauss_cache */
    bool lazy_ratios;            /* re-evaluate at the same time only the elements whose ratio bound
                                    could have reached 1 (equilibrium.c, fs_wedge_element_ratios); on for
                                    element removal (fs_wedge_init) */
    double *node_ratio;          /* per node: the nodal ratio of the split criterion at the current
                                    stresses (wedge/split.c), or only an upper bound of it where
                                    node_ratio_exact is 0; NaN when it must be recomputed: set
                                    NaN for the corners of every element whose stresses or
                                    neighbourhood change */
    uint8_t *node_ratio_exact;   /* per node: 1 where node_ratio holds the ratio itself */
    struct fs_wedge_energy_kept **energy_kept; /* per element: what its last strain energy was computed
                                    from (fs_wedge_element_energy), allocated at its first; NULL before */
    double *ratio_lipschitz;     /* per element: bound of the change of its ratio per cm of change of
                                    its 18 nodal displacements (Euclidean norm) */
    double *ratio_ref_bound;     /* per element: its ratio bound at the last full evaluation (NaN:
                                    none valid) */
    double *ratio_ref_u;         /* 18 per element: its nodal displacements at that evaluation */
    double ratio_ref_coef[FS_WEDGE_PATTERNS]; /* shrinkage and eigenstrain of those evaluations */

    /* Global system: DOFs numbered free first (0 .. n_free - 1), then fixed. */
    int32_t n_free, n_fixed;
    int32_t *dof;                /* 6 per node: index of each node DOF in that numbering */
    int32_t *fixed_node_dof;     /* n_fixed: the node DOF (6 i + k) of each fixed index */
    int32_t dof_cap;             /* nodes dof and fixed_node_dof have room for */
    fs_sparse_matrix k_free;     /* upper CSC of order n_free: K_ff (its row and value arrays have
                                    room for k_free_capacity entries: they grow geometrically as the
                                    mesh is cut, see extend_system) */
    size_t k_free_capacity;
    fs_wedge_coupling k_fb;      /* K_fb: the free rows coupled to each fixed DOF (no fixed-fixed
                                    entries) */
    double *load;                /* 6 per free DOF (load[6 g + q]): unit loads; q = 0..2 shrinkage
                                    (per unit of scale - 1), 3..5 eigenstrain xx, yy, xy (per unit
                                    of eigenstrain) */
    int32_t load_capacity;       /* free DOFs load has room for (it grows geometrically) */
    double *rhs, *x;             /* n_free each: the right-hand side and the free displacements */
    double *u_fixed;             /* n_fixed: displacement of the fixed DOFs */
    double fixed_time;           /* u_fixed[0 .. fixed_exact) hold the fixed displacements at this time
                                    as fs_wedge_prescribe_fixed computes them, and u holds them too */
    int32_t fixed_exact;         /* (so it computes only the rest; 0: none) */
    int32_t *fixed_moved;        /* nodes moved since (fs_wedge_node_moved): theirs are computed again */
    int32_t n_fixed_moved, cap_fixed_moved;
    bool x_synced;               /* x holds u's free displacements (fs_wedge_relax copies them if not) */
    uint8_t *mark;               /* n_free + n_fixed scratch flags, all 0 between calls */
    double assembled_thickness;  /* base thickness (cm) the system was assembled with */
    fs_cholesky *chol;           /* the factor of k_free (CHOLMOD), NULL with CG */
    fs_node_order order;         /* the elimination order kept across cuts (fs_wedge_factorize) */
    int32_t updowns_pending;     /* rank updates applied since the last numeric factorization */
    bool factor_stale;           /* k_free changed since chol was computed (local relaxation defers
                                    the update); the next global solve re-factorizes first */
    double relax_unit;           /* mean edge length (cm) of the living elements at the first
                                    fs_wedge_relax call: the unit of cfg.solver.relax_radius and the
                                    smallest radius (one ring); 0 before that call */
    double relax_radius;         /* local relaxation radius (cm), adapted by fs_wedge_relax */
    double *residual;            /* residual_n: f - K u after the last local relaxation (wedge/relax.c) */
    int32_t residual_n;
    bool residual_valid;         /* residual still describes the model but for the rows of dirty_nodes;
                                    cleared by everything that moves the model except a cut */
    double residual_tau;         /* the acceptance bound it was computed with */
    int32_t *dirty_nodes;        /* nodes whose rows a cut changed since the last local relaxation */
    int32_t n_dirty, cap_dirty;
    struct {                     /* fs_wedge_relax's scratch, at rest between calls (wedge/relax.c) */
        int32_t node_cap, dof_cap;
        double *dist;            /* node_cap: INFINITY */
        uint8_t *flag, *seen;    /* node_cap: 0 */
        int32_t *map;            /* dof_cap: -1 */
        uint8_t *saved;          /* dof_cap: 0; 1 where before holds x as it was before the call */
        double *before;          /* dof_cap */
        int32_t *touched;        /* the free DOFs saved, n_touched of them (room cap_touched) */
        int32_t n_touched, cap_touched;
    } rs;

    int64_t fractures;           /* elements removed so far, or node splits (fracture.method = split) */
    fs_wedge_counters counters;

    /* Element splitting (wedge/split.c, thesis §5.7.3): the crack tips that may still extend. */
    int32_t n_tips, cap_tips;
    int32_t *tip_node;           /* mesh node of each tip */
    double *tip_dir;             /* 3 per tip: unit direction the crack arrived in (model frame) */
    double *tip_scale;           /* per tip: factor on its coarse ratio, the last sub-model ratio over the
                                    coarse ratio then (fracture.tip_submodel, wedge/tips.c), else 1 */
    double tips_unit;            /* mean edge length (cm) of the living elements at the first use of the
                                    sub-model or smoothing radius: their unit; 0 before */
    int64_t griffith_stops;      /* tips retired by the Griffith criterion */
    uint8_t *open;               /* per node: 1 on a boundary edge of the mesh (a crack wall, a tip,
                                    the domain's border), while open_valid (wedge/split.c) */
    bool open_valid;             /* kept up to a change by fs_wedge_apply_change, cleared by any other
                                    change of the mesh's connectivity */
};

/* Builds the model on mesh (borrowed, kept by pointer; its edges and rings must be built, as
 * fs_delaunay does) with cfg's domain, material, growth, shrinkage, time, solver and wedge settings,
 * assembles the system and, with CHOLMOD, analyses and factorizes it. Time starts at 0 with no
 * equilibrium computed (call fs_wedge_equilibrium). Threshold jitter uses cfg->seed; lazy_ratios is on
 * for element removal.
 * Returns 0, or -1 with fs_error: FS_ERR_DATA for bad parameters (growth unsuitable for the domain,
 * E or nu out of range, a degenerate element),
 * FS_ERR_INTERNAL if the factorization fails. On failure the model is freed. */
int fs_wedge_init(fs_wedge_model *w, fs_mesh *mesh, const fs_model_setup *cfg);

/* fs_wedge_init without the assembly: the node and element arrays are filled (materials, thickness
 * factors, prescribed values) but there is no system yet, so the caller may change them and must then
 * call fs_wedge_pin_top, which assembles and factorizes; nothing else may be called before. For
 * models built from another one's data (wedge/tips.c's sub-models). Returns 0 or -1 as fs_wedge_init. */
int fs_wedge_init_unassembled(fs_wedge_model *w, fs_mesh *mesh, const fs_model_setup *cfg);

/* Releases everything the model owns (not the mesh) and zeroes it. */
void fs_wedge_free(fs_wedge_model *w);

/* Prescribes the top nodes with pinned[i] != 0 (n_nodes flags) as fixed too, with the displacement
 * in w->prescribed[6 i + 3 .. 6 i + 5]; bottom nodes are always fixed, at w->prescribed[6 i .. 6 i + 2]
 * plus the growth motion. Re-assembles the system. For patch tests and boundary conditions.
 * Returns 0 or -1 with fs_error. */
int fs_wedge_pin_top(fs_wedge_model *w, const uint8_t *pinned);

/* Brings the model to time t (growth, shrinkage, thickness) and solves for equilibrium: fills w->u,
 * w->stress_top and w->ratio, sets w->time = t. Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) if
 * the solver fails (CG not converging, factorization not positive definite) or FS_ERR_DATA if an
 * element degenerates. */
int fs_wedge_equilibrium(fs_wedge_model *w, double t);

/* The current coefficients of the unit loads w->load: shrinkage (shrink_coef), then growth
 * eigenstrain. */
static inline void fs_wedge_load_coefficients(const fs_wedge_model *w, double coef[FS_WEDGE_PATTERNS])
{
    for (int k = 0; k < 3; k++) {
        coef[k] = w->shrink_coef[k];
        coef[3 + k] = w->eigenstrain[k];
    }
}

/* w->rhs = the loads at the current coefficients net of the fixed DOFs' motion, f - K_fb u_b. */
void fs_wedge_build_rhs(fs_wedge_model *w);

/* The stiffness coupling free DOF g with DOF j (free or fixed) in the assembled system, 0 when the
 * pattern holds no such entry (binary search: O(log) of a column). */
double fs_wedge_system_entry(const fs_wedge_model *w, int32_t g, int32_t j);

/* An equilibrium state of the model at one time, on an unchanged mesh: what fs_wedge_interpolate
 * blends. Owns its arrays; release with fs_wedge_snapshot_free. */
typedef struct {
    double time;
    double thickness;            /* the base thickness the system was assembled with */
    double coef[6];              /* shrink_coef then eigenstrain */
    int32_t n_free, n_fixed, n_nodes, n_elems;
    double *x, *u_fixed;
    double *node_ratio;          /* n_nodes: w->node_ratio (the split criterion's cache) */
    uint8_t *node_ratio_exact;   /* n_nodes: w->node_ratio_exact */
    double *stress_top;          /* 18 per element: w->stress_top */
} fs_wedge_snapshot;

/* Copies the current state (w->time, w->x, w->u_fixed, the load coefficients, the top stresses and
 * the nodal ratio cache) into s, reusing its arrays. */
void fs_wedge_snapshot_take(const fs_wedge_model *w, fs_wedge_snapshot *s);
void fs_wedge_snapshot_free(fs_wedge_snapshot *s);

/* Sets the model to the state at time t between the snapshots a and b (a->time <= t <= b->time, same
 * mesh and numbering), blending displacements and load coefficients linearly, and recomputes the
 * stresses and ratios (no solve). Exact when the loads are affine in time on [a, b] and the stiffness
 * is the same (linear elasticity), which holds between the knots of the shrinkage functions with a
 * constant thickness and no background motion; otherwise an estimate. Returns 0 or -1 with fs_error. */
int fs_wedge_interpolate(fs_wedge_model *w, const fs_wedge_snapshot *a, const fs_wedge_snapshot *b, double t);

/* The largest w->ratio over the living elements (-inf if none): exact when it is over 1, else an
 * upper bound that is itself at most 1. */
double fs_wedge_max_ratio(const fs_wedge_model *w);

/* The exact ratio of element e's largest principal stress at its top Gauss points to its threshold,
 * at the current equilibrium (NaN if e is not alive or the eigen kernel fails). */
double fs_wedge_element_ratio(const fs_wedge_model *w, int32_t e);

/* Element geometry at the current time: x[18] node coordinates in the model's frame (bottom nodes
 * 0..2, top 3..5, see wedge/element.h), unwrapped across periodic seams. */
void fs_wedge_element_coords(const fs_wedge_model *w, int32_t e, double x[18]);

/* Stress (Voigt, MPa) of a living element at natural point (r, s, zeta), at the current equilibrium,
 * net of the shrinkage reference shape and growth eigenstrain. Returns 0 or -1 with fs_error. */
int fs_wedge_element_stress(const fs_wedge_model *w, int32_t e, double r, double s, double zeta, double stress[6]);

/* Nodal stress of the top (top = true) or bottom node of mesh node i (thesis §5.7.1): the average over
 * the living elements around the node of the stress at each element's Gauss point nearest the node.
 * Requires the mesh rings. Returns the number of elements averaged (0: stress zeroed), or -1. */
int fs_wedge_nodal_stress(const fs_wedge_model *w, int32_t node, bool top, double stress[6]);

/* One fracture event at the current time (thesis §5.6.2-5.6.4, Algorithm 8): picks the living
 * element with the largest ratio over 1 (fs_rank_pick, ties by the seed). If its longest edge
 * (fs_refine_tri_size) is at least mesh.min_size, it and every other element over its threshold and
 * at least that size are bisected (Rivara, Algorithm 9) until they are below it, and nothing is
 * removed; otherwise it is removed and the global system updated in place (Algorithm 7), the factor by
 * a low-rank downdate or a re-factorization. Does not re-solve. *removed is set to 1 for a removal, 0
 * for a subdivision. Returns 0, 1 if no element is over its threshold (nothing done), or -1 with
 * fs_error. */
int fs_wedge_fracture(fs_wedge_model *w, int *removed);

/* Removes element e (alive) and updates the system as fs_wedge_fracture does. Returns 0 or -1. */
int fs_wedge_remove(fs_wedge_model *w, int32_t e);

/* Bisects the listed elements (fs_refine_bisect with cfg.mesh.min_size, conforming, so neighbours may
 * be bisected too); with to_min_size, bisects their descendants again until every one is below
 * min_size. Extends the node and element arrays (new nodes interpolate the thickness factor of their
 * edge, new elements inherit their parent's state and materials), updates the global system for the
 * changed elements only (the other entries are kept), then re-analyses and re-factorizes once.
 * *bisected receives the number of triangles bisected (0: nothing changed, all were below min_size).
 * Returns 0 or -1 with fs_error. */
int fs_wedge_subdivide(fs_wedge_model *w, const int32_t *elems, int32_t n, bool to_min_size, int32_t *bisected);

/* A change of the mesh made by the caller in place (element splitting): nodes appended from
 * n_nodes_before on, each interpolated between node_parent[2k] and node_parent[2k + 1] with weight
 * node_weight[k] on the second (0 for a copy of the first: a duplicated node); triangles appended
 * from n_tris_before on, each inheriting the state and materials of tri_parent[k]; and the
 * pre-existing triangles listed (ascending, no duplicates) in changed, whose corners or geometry
 * changed. The mesh's adjacency and rings must already describe the changed mesh. */
typedef struct {
    int32_t n_nodes_before, n_tris_before;
    const int32_t *node_parent;  /* 2 per new node */
    const double *node_weight;   /* 1 per new node */
    const int32_t *tri_parent;   /* 1 per new triangle */
    const int32_t *changed;
    int32_t n_changed;
} fs_wedge_change;

/* The elements with node i as a corner in the mesh as it is now, ascending: found among node_elem's
 * list for i (i < n_nodes), the n_changed listed elements and the triangles from first_new to
 * mesh->n_tris - 1, which must include every element whose corners changed since node_elem was
 * built. With living, removed elements are left out (triangles beyond n_elems count as living). out
 * needs room for all three; returns the count. */
int32_t fs_wedge_elems_at(const fs_wedge_model *w, int32_t i, const int32_t *changed, int32_t n_changed,
                          int32_t first_new, bool living, int32_t *out);

/* Brings the model up to a mesh change (see fs_wedge_change): extends the node and element arrays
 * (new nodes get the interpolated thickness factor, displacement, prescribed values and pin flag of
 * their parents, so w->u is a starting guess everywhere), updates the global system for the changed
 * and new elements only, re-analyses and re-factorizes (with solver.relax = local the factor is
 * dropped instead and w->factor_stale set: the next global solve analyses and factorizes). Does not
 * re-solve. Returns 0 or -1. */
int fs_wedge_apply_change(fs_wedge_model *w, const fs_wedge_change *c);

/* Brings the model up to a change of geometry without a change of the mesh's connectivity (nodes
 * moved in place by the caller, as smoothing does): the listed elements' (ascending, no duplicates)
 * stiffnesses, loads and caches are rebuilt, and so are the entries of the system around their nodes
 * (same pattern) and their stresses at the current displacements; their nodes' residual rows are
 * marked for fs_wedge_relax. The factor is re-factorized, or with solver.relax = local marked stale
 * (w->factor_stale, its analysis kept). Does not re-solve. Returns 0 or -1 with fs_error. */
int fs_wedge_update_geometry(fs_wedge_model *w, const int32_t *elems, int32_t n);

/* Elastic strain energy (MPa cm^3 = J) of living element e at the current equilibrium: half the dot
 * product of its nodal forces and displacements net of the shrinkage reference shape and growth
 * eigenstrain (thesis Algorithm 11). 0 for a removed element; NaN if the element degenerates. Keeps
 * what it computed in w->energy_kept (see equilibrium.c). */
double fs_wedge_element_energy(fs_wedge_model *w, int32_t e);

/* Drops what every element kept of its energy (the next energies are computed afresh). */
void fs_wedge_energy_forget(fs_wedge_model *w);

/* One fracture event by element splitting at the current time (thesis §5.7, Algorithms 10-12; see
 * wedge/split.c): the crack tip with the largest nodal ratio over 1 extends, or if no tip is over its
 * threshold, a new crack starts at the node with the largest ratio over 1. With fracture.tip_submodel
 * the picked tip extends only if its sub-model ratio (fs_wedge_tip_submodel) is over 1 too, in the
 * sub-model's direction; otherwise its tip_scale drops it below 1 and the next tip is tried. With
 * mesh.smooth_radius the new tips' surroundings are smoothed (fs_wedge_smooth). Does not re-solve
 * unless Griffith needs the new equilibrium. *changed is 1 if the mesh changed, 0 if a tip was only
 * retired. Returns 0, 1 if no candidate is over its threshold (nothing done), or -1 with fs_error. */
int fs_wedge_split_event(fs_wedge_model *w, int *changed);

/* The largest nodal ratio among the split candidates at the current equilibrium (tips, their coarse
 * estimate times tip_scale, and nodes off every crack and boundary), -inf if none: what the split
 * method's event search looks at. Fills the nodal ratio cache of every candidate with its ratio, or
 * with an upper bound of it where the bound shows it is not the largest. */
double fs_wedge_split_max_ratio(fs_wedge_model *w);

/* Brings the open flags (w->open, while valid) up to a change of the mesh after which node_elem
 * describes the mesh: recomputes the listed nodes' flags (repeats allowed), which must include every
 * node whose boundary edges may have changed (the corners of the changed and new triangles, and the
 * nodes that lost a triangle to a copy). */
void fs_wedge_open_update(fs_wedge_model *w, const int32_t *nodes, int32_t n);

/* fs_wedge_split_max_ratio of the state at time t blended between the snapshots a and b (taken right
 * after fs_wedge_split_max_ratio on an unchanged mesh, a->time <= t <= b->time), without changing the
 * model. Exact when it is over 1; otherwise some value at most 1. Only the candidates whose ratio
 * exceeds 1 in a or b are evaluated: a ratio is convex along the blend (the largest eigenvalue of a
 * symmetric tensor is a convex function of it, and the stresses blend linearly), so it stays at most
 * the larger of its ends. */
double fs_wedge_split_blend_ratio(fs_wedge_model *w, const fs_wedge_snapshot *a, const fs_wedge_snapshot *b,
                                  double t);

/* Re-factorizes the current matrix now (CHOLMOD; nothing with CG), dropping accumulated updates.
 * Returns 0 or -1 with fs_error. */
int fs_wedge_refactor(fs_wedge_model *w);

/* Runs the model from its current time to t_end (thesis Algorithms 1, 5 and 8): equilibrium,
 * fracture events while an element is over its threshold, otherwise the adaptive time step to the
 * next event (fs_event_find, resolution cfg.time.min_step). Progress through fs_progress. Returns 0
 * or -1 with fs_error. */
int fs_wedge_simulate(fs_wedge_model *w, double t_end);

/* ---- §5.7.7-5.7.9: refinement, sub-models and smoothing around crack tips (wedge/tips.c) ---- */

/* Von Mises discontinuity indicator of every node (thesis §5.7.7, Algorithm 13) at the current
 * stresses (stress_top, so the last equilibrium): the largest minus the smallest von Mises stress of
 * its living elements at their top Gauss point nearest the node, divided by the largest principal
 * stress at any of those points in the layer. indicator (n_nodes entries, may be NULL) gets NaN for a
 * node without living elements and 0 everywhere when the largest principal stress is not positive.
 * Returns the largest indicator (0 if none). */
double fs_wedge_vm_discontinuity(const fs_wedge_model *w, double *indicator);

/* Algorithm 13 at the current time, at most rounds times: the living elements at or above
 * mesh.min_size around every node whose indicator exceeds threshold (> 0) are bisected once
 * (fs_wedge_subdivide, conforming), and the model is solved again (fs_wedge_equilibrium). Stops
 * early when nothing is marked or bisected. *bisected (may be NULL) receives the bisections.
 * Returns 0 or -1 with fs_error. */
int fs_wedge_refine_vm(fs_wedge_model *w, double threshold, int rounds, int32_t *bisected);

/* What one crack-tip sub-model was (fs_wedge_tip_submodel). */
typedef struct {
    int32_t extracted_elems;     /* elements copied from the layer */
    int32_t nodes, elems;        /* of the sub-model after refinement */
    int32_t bisections;          /* Rivara bisections of the refinement */
    double tip_size;             /* largest longest edge among the tip's elements after refinement (cm) */
    double coarse_ratio;         /* the layer's own nodal ratio at the tip (§5.7.1 average) */
} fs_wedge_submodel_info;

/* Local multi-resolution sub-model at node (thesis §5.7.8, Fig. 5.24): the living elements with a
 * corner within radius (cm, along the edges of living elements, fs_wedge_relax_region) of node are
 * copied into a separate mesh and model with the layer's materials, thickness factors and time; the
 * copied nodes beyond the radius are held at the layer's current displacement (bottom nodes keep
 * their prescribed motion); the elements around node are bisected (Rivara) until they are below size
 * (cm); the sub-model is solved. *ratio receives node's nodal ratio there (§5.7.1: its elements'
 * stresses at their Gauss points nearest node averaged, the largest principal stress over their mean
 * threshold) and m (may be NULL) the unit normal of that principal plane; info may be NULL. The layer
 * is not changed (but for w->counters). Returns 0, or -1 with fs_error (a degenerate element, a
 * failed solve); a node without living elements gives *ratio = -inf. */
int fs_wedge_tip_submodel(fs_wedge_model *w, int32_t node, double radius, double size, double *ratio, double m[3],
                          fs_wedge_submodel_info *info);

/* Angle-based smoothing (thesis §5.7.9, Zhou and Shimada) of the nodes within radius (cm, along the
 * edges of living elements) of the centres (n mesh nodes): every such node fully surrounded by living
 * elements (not on a crack wall, a tip or the border) and not pinned is moved, iterations times in
 * ascending order, towards the position that equalises its neighbours' angles, a move kept only if
 * the smallest angle of its triangles does not decrease and it does not cross a periodic seam. The
 * moved elements' geometry, reference shapes and stiffnesses, their stresses at the current
 * displacements and the global system are then updated (fs_wedge_update_geometry); the
 * model is not relaxed (call fs_wedge_relax, which sees the changed rows). *moved (may be NULL)
 * receives the number of nodes moved. Returns 0 or -1 with fs_error. */
int fs_wedge_smooth(fs_wedge_model *w, const int32_t *centres, int32_t n, double radius, int iterations,
                    int32_t *moved);

/* Mean edge length (cm) of the living elements at rest, 1 if there are none: the unit of the
 * relaxation radius (w->relax_unit) and of the crack-tip radii (fs_wedge_tips_unit). */
double fs_wedge_mean_edge(const fs_wedge_model *w);

/* The unit of the sub-model and smoothing radii: w->tips_unit, set at the first call to the mean edge
 * length (cm) of the living elements. */
double fs_wedge_tips_unit(fs_wedge_model *w);

/* design: thesis §5.8, adaptive local relaxation. After a local change of the model (an element
 * removed, split or its nodes duplicated, a node moved) only the nodes near the change move much.
 * The residual f - K u of the current displacements marks the free nodes out of balance (plus the
 * changed nodes given); the marked set grows to every node within the relaxation radius, measured as
 * the shortest path along the edges of living elements (at rest), so cracks (removed elements, duplicated
 * nodes) are barriers; the marked unknowns are solved with all others held (conjugate gradients on
 * the principal submatrix). If the residual then meets the tolerance, the radius shrinks for the next
 * event (x 0.75, not below one mean edge length); else the attempt is repeated at twice the radius,
 * and past a quarter of the unknowns a global solve follows (the radius doubles for the next event,
 * up to the size of the mesh). Stresses and ratios are recomputed only for elements touching a node that
 * moved (all of them after a global solve).
 *
 * Tolerance: a node is out of balance, and the result acceptable, by the largest residual entry
 * against cfg.solver.relax_tolerance times the root mean square of f over the free DOFs (f the
 * right-hand side net of the fixed DOFs' motion). A per-entry bound, unlike a Euclidean one, does not
 * add up the small residuals every accepted event leaves on the rim of its region, so it does not
 * depend on the number of earlier events or on the size of the mesh.
 *
 * Contract: called at the current time w->time after the change, with k_free, k_fb and the loads describing
 * the changed mesh (w->factor_stale set if the factor no longer matches k_free), w->u holding a
 * starting guess for every free DOF (fixed ones are set from their prescribed motion, see
 * fs_wedge_prescribe_fixed), w->x, w->u_fixed and w->rhs sized for the current numbering, node_elem
 * current, and the element caches (gauss_cache) valid.
 * changed_nodes (n mesh nodes, may be NULL with n = 0) are relaxed whatever their residual. Fills
 * w->u, w->x, w->rhs, w->stress_top and w->ratio like fs_wedge_equilibrium. Returns 0, or -1 with
 * fs_error (FS_ERR_INTERNAL when the global solve fails). */
int fs_wedge_relax(fs_wedge_model *w, const int32_t *changed_nodes, int32_t n);

/* The nodes fs_wedge_relax relaxes around the seed nodes (n mesh nodes) at the given radius (cm): every
 * node joined to a seed by a path along the edges of living elements (at rest) no longer than radius, the
 * seeds first (each once). out has room for w->n_nodes entries; returns the count. */
int32_t fs_wedge_relax_region(const fs_wedge_model *w, const int32_t *seeds, int32_t n, double radius, int32_t *out);

/* Frees fs_wedge_relax's scratch (w->rs). */
void fs_wedge_relax_scratch_free(fs_wedge_model *w);

/* Sets the fixed DOFs (bottom nodes, pinned tops) of w->u and w->u_fixed to their prescribed
 * displacement at w->time (growth motion included). */
void fs_wedge_prescribe_fixed(fs_wedge_model *w);

/* Records that a cut moved node (its position): its fixed displacements are computed again. */
void fs_wedge_node_moved(fs_wedge_model *w, int32_t node);

/* Copies the free displacements of the nodes from `first` on from w->u into w->x, and marks x in
 * step with u (x_synced): the caller knows the nodes before first hold them already. */
void fs_wedge_sync_x(fs_wedge_model *w, int32_t first);

/* Recomputes stress_top and the ratios of the listed elements (all when elems is NULL, n ignored;
 * none listed twice: a long list is split across threads) from w->u, then makes exact every ratio
 * fracture decides on (see the ratio field). Returns 0 or -1 with fs_error. */
int fs_wedge_update_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n);

/* ---- --enable-validate (base/error.h: FS_INVARIANT) ---- */

/* Each aborts, naming the broken invariant and `after` (the step just done), unless it holds:
 * the mesh: fs_mesh_check (manifold, consistently oriented, valid adjacency) and as many elements as
 * triangles; the system: K_ff a consistent upper triangle with finite values (fs_sparse_matrix_check),
 * of order n_free; the state: finite displacements of every node and finite top stresses of every
 * living element. Called from #ifdef FS_VALIDATE blocks after every mesh change, assembly and
 * equilibrium. */
void fs_wedge_check_mesh(const fs_wedge_model *w, const char *after);
void fs_wedge_check_system(const fs_wedge_model *w, const char *after);
void fs_wedge_check_state(const fs_wedge_model *w, const char *after);

/* Fragment label of every element (-1 for removed ones, else 0 .. count-1 numbered by their smallest
 * element); returns the count. labels has n_elems entries. */
int32_t fs_wedge_fragments(const fs_wedge_model *w, int32_t *labels);

/* ---- shared by the model's own files (wedge.c, system.c, equilibrium.c, change.c) ---- */

/* Doubles per element of gauss_cache, what the stress check needs at the three top Gauss points:
 * dN/dx (3 x 18) and the strains of the three shrinkage patterns (3 x 3 x 6), so that a stress costs
 * a few hundred flops. Valid while the element's geometry is: refreshed on assembly, thickness change
 * and subdivision (equilibrium.c). */
#define FS_WEDGE_GAUSS_CACHE 108

/* wedge.c: geometry and arrays. The layer's base thickness at time t (cm); element e's 18 node
 * coordinates at a base thickness (bottom nodes, then tops along their normals, unwrapped); the unit
 * displacement patterns whose combinations give an element's loads (three of shrinkage, three of
 * eigenstrain, see wedge.c); the reference-shape displacement at the current shrinkage; the node and
 * element arrays grown to n_nodes and n_elems (new entries initialised). */
double fs_wedge_layer_thickness(const fs_wedge_model *w, double t);
void fs_wedge_coords_at(const fs_wedge_model *w, int32_t e, double base_thickness, double x[18]);
void fs_wedge_patterns(const double x[18], double pat[FS_WEDGE_PATTERNS][18]);
void fs_wedge_shrink_displacement(const fs_wedge_model *w, const double x[18], double u0[18]);
void fs_wedge_grow_arrays(fs_wedge_model *w, int32_t n_nodes, int32_t n_elems);

/* system.c: the global system. DOF numbering (free first, in node order), the DOF of element e's
 * node a (0..5), the node element lists (built, or updated after a change: see system.c), the living
 * elements at node i, element e's coordinates and stiffness, whether the same inputs give e the same
 * stiffness again (not so while a stiffness fitted in thickness waits for its fit: see k_parts),
 * element e's stiffness and unit loads, the slot of entry (i, j) of an upper CSC
 * matrix (-1 if absent), the coupling's column operations, the whole assembly, re-adding elements into
 * the pattern (only the marked DOFs' entries when only is not NULL), new values on the same pattern,
 * and the CHOLMOD factorization (with a new analysis when analyze is set). Return 0 or -1 with
 * fs_error where they return int. */
void fs_wedge_number_dofs(fs_wedge_model *w);
void fs_wedge_number_appended(fs_wedge_model *w, int32_t n0);
int32_t fs_wedge_elem_dof(const fs_wedge_model *w, int32_t e, int a);
void fs_wedge_build_node_elems(fs_wedge_model *w);
void fs_wedge_update_node_elems(fs_wedge_model *w, int32_t n0, int32_t e0, const int32_t *changed, int32_t n_changed,
                                const int32_t *lost, int32_t nl);
int32_t fs_wedge_alive_at_node(const fs_wedge_model *w, int32_t i);
int fs_wedge_element_stiffness(const fs_wedge_model *w, int32_t e, double base_thickness, double x[18], double K[324]);
bool fs_wedge_stiffness_repeats(const fs_wedge_model *w, int32_t e);
int fs_wedge_element_system(const fs_wedge_model *w, int32_t e, double base_thickness, double K[324],
                            double loads[FS_WEDGE_PATTERNS][18]);
int32_t fs_wedge_find_entry(const fs_sparse_matrix *m, int32_t i, int32_t j);
void fs_wedge_coupling_free(fs_wedge_coupling *c);
void fs_wedge_coupling_resize(fs_wedge_coupling *c, int32_t n);
void fs_wedge_coupling_insert(fs_wedge_coupling *c, int32_t k, int32_t row);
void fs_wedge_coupling_compact(fs_wedge_coupling *c);
int fs_wedge_build_system(fs_wedge_model *w);
int fs_wedge_readd(fs_wedge_model *w, const int32_t *elems, int32_t n, const uint8_t *only);
int fs_wedge_refill_system(fs_wedge_model *w, double base_thickness);
int fs_wedge_factorize(fs_wedge_model *w, bool analyze);

/* equilibrium.c: the element caches of the stress check (gauss_cache, edge_rest) of the listed
 * elements, and their stresses and ratios (see the ratio field; none listed twice). Return 0 or -1
 * with fs_error. */
int fs_wedge_refresh_cache(fs_wedge_model *w, const int32_t *elems, int32_t n);
int fs_wedge_element_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n_elems);

#endif
