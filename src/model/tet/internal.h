/* The tetrahedral model's state and what its files (and white-box tests) share. */
#ifndef FS_MODEL_TET_INTERNAL_H
#define FS_MODEL_TET_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "field/growth.h"
#include "geom/tetcut.h"
#include "geom/tetmesh.h"
#include "model/model.h"
#include "model/tet/tet.h"
#include "solve/sparse.h"

/* design: loads. The layer is linear, so its state at time t is the sum over a few load cases k of
 * a coefficient c_k(t) times the displacement U_k that case makes alone; each U_k is solved once per
 * mesh (and brought along locally after every fracture), and a time costs no solve:
 *   SHRINK_BOTTOM, SHRINK_TOP  eigenstrains of the drying layer (thesis Fig. 3.10, as the wedge
 *                              model: in the layer's plane -((1 - zeta) bottom(t) + zeta top(t)),
 *                              across it -(bottom(t) + top(t)) / 2), coefficients bottom(t), top(t)
 *   EIGEN                      a constant eigenstrain eps0 with coefficient (F(t) - I)_ij: planar or
 *                              cylinder growth of a periodic domain, as the layer's eigenstrain
 *                              -(F - I) (field/growth.h), so the tile stays periodic
 *   MOVE                       the bonded nodes displaced by move (X - centre) with coefficient
 *                              (J(t) - I)_ij: the substrate's growth on a plane that does not wrap
 *                              and on the sphere (fs_growth_flow is linear in X)
 * Cases whose coefficient stays 0 over the run are left out. */
typedef enum { FS_TET_SHRINK_BOTTOM = 0, FS_TET_SHRINK_TOP, FS_TET_EIGEN, FS_TET_MOVE } fs_tet_load_kind;

#define FS_TET_LOADS 8

typedef struct {
    fs_tet_load_kind kind;
    double eps0[6];       /* EIGEN: the eigenstrain per unit coefficient (Voigt, engineering shears) */
    double move[9];       /* MOVE: displacement per unit coefficient = move (X - centre), row-major */
    double centre[3];
    int ci, cj;           /* EIGEN, MOVE: the coefficient is entry (ci, cj) of F - I or J - I */
    double scale;         /* a typical element force of the case alone (MPa cm^2), for residual tests */
} fs_tet_load;

/* Counters and timings for the report and the benchmark. */
typedef struct {
    int64_t splits, debonds, failed_splits;
    int64_t searches, evaluations; /* per-node event searches and ratio evaluations */
    int64_t local_solves, local_unknowns, global_solves, direct_solves;
    double mesh_seconds, solve_seconds, local_seconds, search_seconds, cut_seconds;
} fs_tet_counters;

struct fs_tet {
    fs_model_setup cfg;
    fs_tet_params par;
    fs_tetmesh mesh;            /* the layer (material coordinates) */
    fs_growth_field growth;
    double spacing;             /* mean point spacing of a layer (cm) */
    double mean_edge;           /* mean edge length of the initial mesh (cm) */
    double end;                 /* time.end */
    double time;                /* simulated time reached */

    /* per tetrahedron */
    double *grad;               /* 12: shape function gradients */
    double *vol;                /* volume (cm^3) */
    double *lambda, *mu;        /* Lame's constants (MPa) */
    double *eps0;               /* 6 per load: the eigenstrain of each load case */
    double *stress;             /* 6 per load: the stress of each load case alone (MPa) */
    double *split_ref;          /* proportional loads: 12, the stress at c_ref and its tensile part */
    int32_t cap_tets;

    /* per node */
    double *u;                  /* 3 per load: the displacement of each load case (node-major) */
    double *threshold;          /* threshold stress (MPa), jittered and mapped */
    double *area;               /* bonded nodes: their share of the bonded bottom (cm^2) */
    uint8_t *bonded;            /* 1: fixed to the substrate */
    int32_t *dof;               /* 3: free unknown, or -1 */
    double *t_cross;            /* the node's next fracture time (INFINITY: none before the end) */
    int32_t cap_nodes;
    int32_t n_free;

    int n_loads;
    fs_tet_load load[FS_TET_LOADS];
    bool proportional;          /* every c(t) over the run is alpha(t) c_ref with alpha >= 0: the
                                   stresses scale together, and so does every node's ratio */
    double c_ref[FS_TET_LOADS];
    double *r_ref;              /* per node, proportional loads: its ratio at c_ref */
    fs_tetcut_params snap;      /* the cuts' snapping (cm, radians) */
    double reg;                 /* a spring to the rest position on every free unknown (MPa cm),
                                   a billionth of an element's stiffness: no piece can float */

    fs_tetcut_result cut;       /* scratch of the last cut */
    int32_t *stamp;             /* scratch per node: the relaxation's marks (compared with stamp_now) */
    int32_t stamp_now;
    int32_t *dof_map;           /* scratch per node: its number in a local system, or -1 */
    int32_t cap_map;
    int32_t *tet_slot;          /* scratch per tetrahedron: its place in a local system's list */
    int32_t cap_slot;
    int32_t *region;            /* scratch per node: a relaxation's region (geom/region.h) */
    double *dist;               /* scratch per node: its distances, INFINITY between searches */
    int32_t cap_region;
    int32_t *tet_stamp;         /* scratch per tetrahedron: marks (compared with tet_stamp_now) */
    int32_t tet_stamp_now, cap_tet_stamp;
    int64_t events;
    fs_tet_counters counters;
};

/* tet.c */

/* Everything fs_tet_create does after meshing, on mesh (taken over): materials, bonding of the
 * bottom (unless bond_bottom is false: a free layer, for tests), loads and the global solve. Returns
 * 0 or -1 with fs_error; on failure s is freed. */
int fs_tet_init(fs_tet *s, fs_tetmesh *mesh, const fs_model_setup *cfg, bool bond_bottom);
void fs_tet_free(fs_tet *s);

/* The load coefficients c_k(t). */
void fs_tet_coefficients(const fs_tet *s, double t, double *c);

/* Proportional loads: alpha(t), so that c(t) = alpha(t) c_ref. */
double fs_tet_alpha(const fs_tet *s, double t);

/* The eigenstrain of load k in tetrahedron t, from its kind and the tetrahedron's place in the layer. */
void fs_tet_load_eigenstrain(const fs_tet *s, int k, int32_t t, double eps0[6]);

/* Geometry (gradients, volume) of tetrahedron t from the mesh. Returns 0, or -1 with fs_error for a
 * tetrahedron without volume. */
int fs_tet_update_geometry(fs_tet *s, int32_t t);

/* The stress (Voigt) of load case k's displacements in tetrahedron t, its eigenstrain taken off. */
void fs_tet_load_stress(const fs_tet *s, int32_t t, int k, double sigma[6]);

/* The stresses of every load in tetrahedron t from the current displacements. */
void fs_tet_update_stress(fs_tet *s, int32_t t);

/* Numbers the free unknowns (nodes not bonded), keeping those already numbered. */
void fs_tet_number_dofs(fs_tet *s);

/* Assembles and solves the whole layer for every load (CHOLMOD), then every element's stresses.
 * Returns 0 or -1 with fs_error(FS_ERR_INTERNAL). */
int fs_tet_solve_global(fs_tet *s);

/* The displacement of node i at coefficients c (3 values). */
void fs_tet_displacement(const fs_tet *s, int32_t i, const double *c, double out[3]);

/* The stress of tetrahedron t at coefficients c. */
void fs_tet_stress_at(const fs_tet *s, int32_t t, const double *c, double out[6]);

/* The outward normal of the layer at node i (up on the plane and cylinder, radial on the sphere). */
void fs_tet_normal(const fs_tet *s, int32_t i, double n[3]);

/* Grows the per-node and per-tetrahedron arrays to the mesh's counts (new entries zeroed). */
void fs_tet_grow(fs_tet *s);

/* fracture.c */

/* The largest ratio of node i at coefficients c: its separation tensor's largest eigenvalue over its
 * threshold times its cross-section across that eigenvector (fracture), or the pull on its bond over
 * the bond's strength times its area (a bonded node with a bond strength). *kind: 0 fracture, 1
 * bond; normal (may be NULL) the fracture plane's normal. c NULL: at c_ref, from the elements'
 * cached split (proportional loads only). */
double fs_tet_node_ratio(const fs_tet *s, int32_t i, const double *c, int *kind, double normal[3]);

/* Node i's ratio at the current time (coefficients c): from r_ref when the loads are proportional. */
double fs_tet_ratio_now(const fs_tet *s, int32_t i, const double *c);

/* Searches node i's next fracture time from t0 (into s->t_cross). Returns 0 or -1. */
int fs_tet_search_node(fs_tet *s, int32_t i, double t0);

/* Splits node i along the plane with the given normal and brings the state along (new nodes'
 * displacements, elements, local relaxation, searches). Returns 1 split, 0 no split possible, -1. */
int fs_tet_split(fs_tet *s, int32_t i, const double normal[3]);

/* Frees bonded node i from the substrate and relaxes around it. Returns 0 or -1. */
int fs_tet_debond(fs_tet *s, int32_t i);

/* Relaxes the displacements of every load around the given nodes (they and their neighbours changed)
 * until the residual outside the relaxed region is small, then updates the stresses and event
 * searches of everything the relaxation moved. Returns 0 or -1. */
int fs_tet_relax_local(fs_tet *s, const int32_t *nodes, int32_t n);

#endif
