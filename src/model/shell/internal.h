/* Inside the shell model (Gingold et al. 2004): its state, and what its files and white-box tests share. */
#ifndef FS_MODEL_SHELL_INTERNAL_H
#define FS_MODEL_SHELL_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "base/threads.h"
#include "field/growth.h"
#include "geom/mesh.h"
#include "model/model.h"
#include "solve/node_order.h"
#include "solve/sparse.h"

/* design: the shell is the middle surface of a layer of thickness h, one vertex per mesh node, in 3-D
 * (plane z = 0; cylinder and sphere embedded by fs_domain_embed; a mesh domain as loaded). Its
 * energy (Gingold et al. §"Elasticity", Koiter's shell with their discrete strains) is
 *
 *   membrane  per triangle  A h W(Em - Em* - Pm),          Em = (F^T F - I) / 2, Green strain
 *   bending   per triangle  A h^3/12 W(Ec - kappa* I - Pc), Ec = sum_i (phi_i - phi0_i) l_i / (2 A) t_i t_i^T
 *   bond      per node      (x - a)^T K (x - a) / 2,        K = area (k_t (I - n n^T) + k_n n n^T)
 *
 * with W(e) = Y / (2 (1 - nu^2)) ((1 - nu) tr(e^2) + nu tr(e)^2) (plane stress, St Venant-Kirchhoff
 * in the Green strain), A, l_i, t_i the rest area, edge lengths and unit in-plane normals of the
 * edges, phi = 2 tan(theta / 2) of the signed dihedral angle theta of each interior edge (positive
 * where the surface is convex on its normal side), phi0 its rest value. Every tensor is 2x2 in the
 * triangle's rest frame (frame: e1 along its first edge, e2 = n x e1), stored (xx, yy, xy).
 * The paper writes Ec with the scrambled factor "(delta phi_i) / (2 A l_i) t_i (x) t_i" for t_i of
 * length l_i; with unit t_i that is l_i / (2 A): each edge's integrated curvature phi l shared
 * half-and-half by its two triangles and averaged over the area (derived, the text is unreadable).
 *
 * The rest shape changes with time (the growth and shrinkage fields, SPEC §4): Em* is the membrane
 * eigenstrain (the mean of the top and bottom shrinkage eigenstrains, plus on periodic domains the
 * growth eigenstrain -(F_g - I) as the wedge model takes it), kappa* the rest-curvature change of a
 * top/bottom mismatch: the layer is two bonded halves whose free shrinkage differs, whose free
 * curvature is 3 (e_top - e_bottom) / (2 h) (Timoshenko's bilayer of equal halves). The eigenstrains
 * enter additively in the Green strain (small-strain approximation of the grown rest metric). On the
 * plane, sphere, cylinder (its own growth) and mesh, growth moves the anchors a instead: each vertex
 * is bonded to the point of the growing surface it started on (fs_growth_flow).
 *
 * Periodic plane and cylinder along its axis: triangles across the seam use the mesh's corner
 * shifts, each shift a fixed 3-D offset (period), so one set of vertices wraps.
 *
 * Units: lengths cm, Y in MPa, stresses MPa (the preset's kPa are converted), forces MPa cm^2,
 * energies MPa cm^3 = J. */

/* How background growth loads the shell. */
typedef enum { FS_SHELL_GROWTH_NONE = 0, FS_SHELL_GROWTH_MOVE, FS_SHELL_GROWTH_EIGENSTRAIN } fs_shell_growth_mode;

/* Counters and timings, for logs and benchmarks. */
typedef struct {
    int64_t newton_iterations;  /* Hessian factorizations of Newton's method */
    int64_t back_solves;        /* Newton steps (back-substitutions with the current factor) */
    int64_t line_search_cuts;   /* step halvings of the line search */
    int64_t shifted;            /* factorizations retried with a diagonal shift (Hessian not positive) */
    int64_t solves;             /* equilibria */
    int64_t analyses;           /* symbolic analyses (new sparsity pattern after a cut) */
    int64_t orderings;          /* of which the whole shell's ordered afresh (METIS) */
    int64_t plastic_updates;    /* triangles whose plastic strain changed, summed over steps */
    int64_t steps;              /* accepted time steps */
    int64_t search_evaluations; /* equilibria of the event search */
    int64_t cuts;               /* fracture events: crack segments cut */
    int64_t local_relaxations;  /* local Newton solves after cuts (shell/relax.c) */
    int64_t local_nodes;        /* their nodes, summed */
    int64_t global_fallbacks;   /* relaxations that needed the whole shell */
    double relax_seconds;       /* time in fs_shell_relax, fallbacks included */
    int64_t budges;             /* vertices budged onto a crack line */
    double assemble_seconds, factor_seconds, solve_seconds, fracture_seconds;
} fs_shell_counters;

/* One element's Hessian block: the nodes of its stencil (k of them) and its 3 k x 3 k matrix. */
typedef struct {
    int32_t nodes[6];
    int k;
    double m[18 * 18];
} fs_shell_element;

/* A Newton system over some of the shell's DOFs: the whole shell, or the nodes around a change for a
 * local relaxation (shell/relax.c), whose energy is then summed over the triangles and bonds that
 * depend on those nodes (the rest of the energy is constant while only they move). */
typedef struct {
    const int32_t *tris;           /* the triangles whose energy counts, or NULL for all */
    int32_t n_tris;
    const int32_t *nodes;          /* the nodes whose bond counts, or NULL for all */
    int32_t n_nodes;
    int32_t n_free;                /* unknowns */
    int32_t *dof;                  /* 3 per mesh node: unknown of each component, or -1 (held) */
    bool pattern_valid;            /* K's pattern, slots and analysis fit the mesh and dof */
    fs_sparse_matrix K;            /* upper CSC of the Hessian over the unknowns */
    int32_t *slots;                /* compression slots of the element blocks, in assembly order */
    size_t n_slots;
    fs_cholesky *chol;
    bool factored;                 /* chol holds the factor of a recent Hessian of the current pattern */
} fs_shell_system;

/* The triangles and nodes of a system's scope, the q-th of each. */
static inline int32_t fs_shell_scope_tris(int32_t n_tris, const fs_shell_system *sys)
{
    return sys->tris ? sys->n_tris : n_tris;
}
static inline int32_t fs_shell_scope_tri(const fs_shell_system *sys, int32_t q)
{
    return sys->tris ? sys->tris[q] : q;
}
static inline int32_t fs_shell_scope_nodes(int32_t n_nodes, const fs_shell_system *sys)
{
    return sys->nodes ? sys->n_nodes : n_nodes;
}
static inline int32_t fs_shell_scope_node(const fs_shell_system *sys, int32_t q)
{
    return sys->nodes ? sys->nodes[q] : q;
}

/* Releases a system's arrays and factor and zeroes it. */
void fs_shell_system_free(fs_shell_system *sys);

/* Scratch of the local relaxations (shell/relax.c), kept across them: dof is -1 and in 0 between
 * uses, so a relaxation touches only its own nodes and triangles. */
typedef struct {
    int32_t *dof;                  /* 3 per node (cap_nodes): a local system's unknowns */
    uint8_t *in;                   /* per triangle (cap_tris): in the scope being built */
    int32_t *tris;                 /* per triangle: the scope's triangles */
    int32_t cap_nodes, cap_tris;
} fs_shell_local;

struct fs_shell {
    fs_mesh *mesh;                 /* borrowed; fracture cuts it in place */
    fs_model_setup cfg;            /* copy of the setup (the pointers in it are borrowed) */
    fs_growth_field growth;
    fs_shell_growth_mode growth_mode;
    double period[2][3];           /* 3-D offset of one period along the mesh's shift axes */
    double time;                   /* time of the current state */

    /* What the loads are at time: set by fs_shell_set_time. */
    double thickness;              /* base thickness (cm), times each triangle's factor */
    double em_iso;                 /* isotropic membrane eigenstrain (mean shrinkage eigenstrain) */
    double kappa_h;                /* kappa* times the local thickness: 3 (e_top - e_bottom) / 2 */
    double growth_eps[4];          /* eigenstrain mode: the growth strain F_g - I (2x2, domain axes) */

    /* Nodes (vertices). */
    int32_t n_nodes, cap_nodes;
    double *rest;                  /* 3 per node: rest (material) position, 3-D, cm */
    double *x;                     /* 3 per node: current position */
    double *anchor0;               /* 3 per node: the surface point it is bonded to, domain coordinates at t = 0 */
    double *anchor;                /* 3 per node: that point at the current time, 3-D */
    double *normal;                /* 3 per node: rest unit normal (area-weighted mean of its triangles') */
    double *node_area;             /* per node: a third of the rest area of its triangles (cm^2) */
    uint8_t *pin;                  /* per node: bit k set when component k is held at x (tests) */
    double *f_ext;                 /* 3 per node: dead load (MPa cm^2), all 0 unless a test sets it */
    double *tip_dir;               /* 3 per node: for a crack tip (the inner end of a crack), the unit
                                      direction (rest, 3-D) the crack arrived in; zero for other nodes */
    double *rate;                  /* 3 per node: d x / d t over the last accepted step (guesses) */
    bool rate_valid;               /* rate fits the mesh and the last step */
    int32_t *origin;               /* per node: the node it was duplicated from by a crack (itself if
                                      none), so the two walls of a crack are the boundary edges with
                                      the same pair of origins */
    double unit;                   /* mean rest edge length of the mesh as built (cm): the scale of the
                                      shortest edge a crack may make */
    double bond_t, bond_n;         /* bond stiffness per unit area, tangential and normal (MPa / cm) at
                                      the base thickness and Young's modulus */

    /* Triangles. */
    int32_t n_tris, cap_tris;
    double *uv;                    /* 6 per triangle: texture coordinates of its corners */
    double *frame;                 /* 6 per triangle: rest frame vectors e1, e2 (3-D) */
    double *dm_inv;                /* 4 per triangle: inverse of the rest edge matrix [p1 - p0, p2 - p0] in the frame */
    double *area0;                 /* per triangle: rest area (cm^2) */
    double *bend_c;                /* 3 per triangle: l_i / (2 A) of edge i (corners i, i + 1) */
    double *bend_t;                /* 9 per triangle: t_i t_i^T (xx, yy, xy) of edge i in the frame */
    double *young;                 /* per triangle: Young's modulus (MPa), map applied */
    double *threshold;             /* per triangle: threshold stress (MPa), map and jitter applied */
    double *thick_factor;          /* per triangle: factor of the base thickness (map) */
    double *plastic;               /* 6 per triangle: plastic strain Pm (xx, yy, xy) and Pc (1/cm) */
    double *axes;                  /* 4 per triangle (eigenstrain mode): R[2a + i] = e_a . d_i, the frame
                                      components of the domain's unit axes d_x, d_y at the triangle, so
                                      a domain tensor T is R T R^T in the frame */

    /* Hinges (interior edges), stored at the owner half-edge 3 t + i of each (energy.c). */
    int32_t *twin;                 /* 3 per triangle: the half-edge across edge i (running the other
                                      way), or -1 on a border or crack */
    int32_t *hinge;                /* 4 per half-edge, at owners: nodes a, b (the edge, a -> b in the
                                      owner's triangle), c1 (opposite in it), c2 (in the twin's) */
    double *hinge_off;             /* 12 per half-edge, at owners: 3-D offsets (periods) added to the
                                      four nodes' positions to unwrap the hinge in the owner's frame */
    double *phi0;                  /* per half-edge, at owners: rest phi */
    double *phi;                   /* per half-edge, at owners: phi at the positions of the last
                                      evaluation */
    double *dphi;                  /* 12 per half-edge, at owners: its gradient there */
    double *gphi;                  /* 3 per triangle, at owners: dE/dphi (scratch of the Hessian) */
    double *terms;                 /* 13 per triangle: its energy terms (scratch of an evaluation) */
    double *face_ratio;            /* per triangle: its fracture ratio (scratch of fs_shell_max_ratio) */
    fs_shell_element *ke;          /* element matrices of a chunk of a Hessian's assembly (scratch) */
    int32_t ke_cap;

    fs_shell_system sys;           /* the whole shell's system (no scope) */
    double *grad;                  /* 3 per node: gradient of the energy at x */
    double *work;                  /* scratch: 2 n_free + 6 n_nodes (reallocated to fit) */
    size_t work_size;
    fs_shell_local local;          /* scratch of the local relaxations */
    fs_node_order order;           /* the whole shell's elimination order, kept across cuts */

    int64_t fractures;
    fs_shell_counters counters;
};

/* ---- hinge.c: the discrete bending strain of an edge ---- */

/* phi = 2 tan(theta / 2) of the hinge x[0..2] = a, x[3..5] = b, x[6..8] = c1, x[9..11] = c2 (triangles
 * (a, b, c1) and (b, a, c2), counter-clockwise), theta the signed angle between their normals,
 * positive when c2 lies below the plane of (a, b, c1) (convex on the normal side). grad (12, may be
 * NULL) receives d phi / d x; hess (144, row-major, may be NULL) d^2 phi / d x^2. Returns phi, NaN
 * for a degenerate triangle (zero area) or theta = +-pi. */
double fs_shell_hinge_phi(const double x[12], double *grad, double *hess);

/* ---- energy.c ---- */

/* The owner of the hinge across half-edge h (3 t + i): the smaller of h and its twin; -1 on a
 * border or crack. */
int32_t fs_shell_owner(const fs_shell *s, int32_t h);

/* Fills the rest data of the n listed triangles (all when tris is NULL) from the rest positions: the
 * twins of their half-edges (from the mesh's adjacency, and of the half-edges that were across them:
 * a new triangle's twins must be -1 on entry), frames, areas, bending terms, and the hinges of their
 * edges with their rest phi. Returns 0, or -1 with fs_error(FS_ERR_DATA) for a degenerate triangle or
 * a rest surface folded onto itself. */
int fs_shell_rest_geometry_of(fs_shell *s, const int32_t *tris, int32_t n);

/* fs_shell_rest_geometry_of every triangle. */
int fs_shell_rest_geometry(fs_shell *s);

/* The 3-D position of corner c of triangle t at the node positions p (3 per node): p plus the
 * corner's periods. */
void fs_shell_corner(const fs_shell *s, const double *p, int32_t t, int c, double out[3]);

/* The membrane strain Em (Green strain, xx, yy, xy) and bending strain Ec (change of the shape
 * operator) of triangle t at the node positions p, in the triangle's rest frame, from the current
 * edge phi in s->phi (call fs_shell_update_phi first). */
void fs_shell_strains(const fs_shell *s, const double *p, int32_t t, double em[3], double ec[3]);

/* Runs fn over the items [0, n) on several threads in fixed parts (fs_parallel_ranges), or on the
 * calling thread alone for few items (energy.c design). fn(ctx, i0, i1) must write only the slots of
 * its own items. */
void fs_shell_parallel(int32_t n, fs_range_fn fn, void *ctx);

/* Recomputes s->phi (and s->dphi when with_grad) of every hinge at positions p. */
void fs_shell_update_phi(fs_shell *s, const double *p, bool with_grad);

/* Recomputes s->phi of the hinges of the n listed triangles at positions p. */
void fs_shell_update_phi_of(fs_shell *s, const double *p, const int32_t *tris, int32_t n);

/* The eigenstrains of triangle t at the current time: membrane (xx, yy, xy) and curvature. */
void fs_shell_eigenstrain(const fs_shell *s, int32_t t, double em[3], double ec[3]);

/* The elastic strains of triangle t (total minus eigenstrain minus plastic) at positions p (phi as in
 * fs_shell_strains). */
void fs_shell_elastic_strains(const fs_shell *s, const double *p, int32_t t, double em[3], double ec[3]);

/* Local thickness (cm) of triangle t at the current time. */
double fs_shell_tri_thickness(const fs_shell *s, int32_t t);

/* Total energy at positions p (3 per node): membrane, bending, bond, minus the work of f_ext, over
 * sys's scope (the whole shell for &s->sys). With grad (3 per node, may be NULL) its gradient (exact
 * for the nodes the scope was made for; the whole array is overwritten); with hessian, the Hessian
 * over sys's unknowns into sys->K (the pattern is built first if not valid). Returns the energy, NaN
 * for a degenerate state. */
double fs_shell_energy_in(fs_shell *s, fs_shell_system *sys, const double *p, double *grad, bool hessian);

/* fs_shell_energy_in over the whole shell. */
double fs_shell_energy(fs_shell *s, const double *p, double *grad, bool hessian);

/* ---- solve.c ---- */

/* Numbers the free DOFs of the whole shell (pin) and invalidates its pattern. */
void fs_shell_number_dofs(fs_shell *s);

/* Equilibrium of sys's unknowns (the others held) at the current time and loads, by Newton's method
 * with a backtracking line search from s->x (updated in place). Returns 0, or -1 with
 * fs_error(FS_ERR_INTERNAL) when it does not converge. */
int fs_shell_solve(fs_shell *s, fs_shell_system *sys);

/* fs_shell_solve of the whole shell. */
int fs_shell_equilibrium(fs_shell *s);

/* The largest absolute gradient component over the whole shell's unknowns at s->x (the residual
 * force, MPa cm^2). */
double fs_shell_residual(fs_shell *s);

/* ---- shell.c ---- */

/* Sets s->time = t and the loads at t: thickness, eigenstrains, anchors. */
void fs_shell_set_time(fs_shell *s, double t);

/* Rest normals and lumped areas of the nodes from the rest geometry of their triangles. */
void fs_shell_node_geometry(fs_shell *s);

/* Builds the state on mesh like fs_shell_create, without solving; for white-box tests, which may then
 * pin nodes, set loads and call fs_shell_equilibrium. */
fs_shell *fs_shell_build(fs_mesh *mesh, const fs_model_setup *setup);

/* Grows the state's arrays to room for the given numbers of nodes and triangles (new entries zero). */
void fs_shell_reserve(fs_shell *s, int32_t nodes, int32_t tris);

/* ---- fracture.c ---- */

/* The fracture ratio of face t at the current state (phi up to date, fs_shell_update_phi): the
 * largest principal plane stress at z = +-h/2 over the face's threshold; m (may be NULL) receives
 * the unit principal direction in the face's frame (the crack's normal). NaN on failure. */
double fs_shell_face_ratio(const fs_shell *s, int32_t t, double m[2]);

/* Every face's ratio at the current state into ratio (n_tris), its direction into m (2 per face, may
 * be NULL) and the plane stress the ratio reads, as a 3-D Voigt stress (tensor shears) in the
 * model's frame, into stress (6 per face, zero where not finite; may be NULL); updates phi first. */
void fs_shell_face_ratios(fs_shell *s, double *ratio, double *m, double *stress);

/* The largest face ratio at the current state (updates phi); ratio (n_tris, may be NULL) gets each. */
double fs_shell_max_ratio(fs_shell *s, double *ratio);

/* ---- crack.c ---- */

/* One batch of fracture events at the current time: the faces over their threshold, the highest
 * ratio first (ties by the seed, fracture/rank.h), each cut unless a face near it was cut in this
 * batch (its stresses are out of date until the next equilibrium). Does not re-solve. *seeds
 * (caller frees) receives the *n_seeds nodes the cuts made or changed faces at. Returns the number of
 * cracks opened, or -1 with fs_error. */
int32_t fs_shell_fracture_batch(fs_shell *s, int32_t **seeds, int32_t *n_seeds);

/* ---- relax.c ---- */

/* Brings the shell back to equilibrium after cuts near the seeds (n_seeds nodes): a local relaxation
 * of the nodes around them, grown until the residual anywhere is below solver.relax_tolerance of the
 * residual it started from, else (or with solver.relax = global) the whole shell. Returns 0 or -1. */
int fs_shell_relax(fs_shell *s, const int32_t *seeds, int32_t n_seeds);

/* ---- plastic.c ---- */

/* The plastic update of every triangle at the current state (Gingold et al. §"Plasticity", derived):
 * where the yield function is positive, the plastic strain moves along the flow direction until it is
 * zero. Returns the number of triangles updated; *excess (when not NULL) gets the largest relative
 * amount by which one was over yield (the yield function over eps0), 0 when none was. */
int32_t fs_shell_plastic_update(fs_shell *s, double *excess);

/* ---- surface.c ---- */

/* Fragment label of every triangle (connected through shared edges), numbered 0 .. count - 1 by their
 * smallest triangle; returns the count. label has n_tris entries. */
int32_t fs_shell_fragments(const fs_shell *s, int32_t *label);

#endif
