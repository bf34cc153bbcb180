/* The one model interface: what sim needs from every crack model, dispatched by a switch on the kind. */
#ifndef FS_MODEL_MODEL_H
#define FS_MODEL_MODEL_H

#include <stdint.h>

#include "field/field.h"
#include "field/map.h"
#include "geom/mesh.h"
#include "geom/surface.h"
#include "model/params.h"
#include "model/shell/shell.h"
#include "model/springs/springs.h"
#include "model/tet/tet.h"
#include "model/voronoi.h"
#include "model/wedge/wedge.h"

/* design: a model is a state that grows cracks over simulated time on a mesh that sim samples and
 * triangulates. sim owns the one time loop (and its time-lapse frames):
 *
 *     fs_model_init(&m, &mesh, &setup)            build the state at t = 0 (no equilibrium yet)
 *     for each frame time t_k (the last is time.end):
 *         fs_model_advance(&m, t_k)                simulate from the current time to t_k
 *         fs_model_surface(&m, &surface)           the texture-space surface of the state now
 *         fs_model_stats(&m)                       fractures and time so far
 *     fs_model_solid(&m, &solid)                 optional: the 3-D pieces of the final state
 *     fs_model_report(&m); fs_model_free(&m)
 *
 * so a run with frames and one without differ only in where advance stops. Everything a model reads
 * is in fs_model_setup: the shared physical sections (material, growth, shrinkage, fracture, time,
 * solver, mesh limits), the grey-level maps already loaded and wrapped by sim (a model never reads a
 * file), the seed, and one parameter struct per model. The mesh is borrowed; a model may refine or
 * cut it in place (the caller frees it after fs_model_free).
 *
 * How to add a model (the template the shell and tetrahedral models follow):
 *   1. src/model/NAME/NAME.h, its public header, small: fs_NAME_params with fs_NAME_params_default(),
 *      an opaque `typedef struct fs_NAME fs_NAME;` and the five calls of the interface:
 *          fs_NAME *fs_NAME_create(fs_mesh *mesh, const struct fs_model_setup *setup);  NULL + fs_error
 *          int  fs_NAME_advance(fs_NAME *s, double t);                                  0 / -1 + fs_error
 *          int  fs_NAME_surface(const fs_NAME *s, fs_surface *out);                     0 / -1 + fs_error
 *          fs_model_info fs_NAME_info(const fs_NAME *s);
 *          void fs_NAME_report(const fs_NAME *s);                                       counters, fs_debug
 *          void fs_NAME_destroy(fs_NAME *s);
 *      A model whose fragments are real solids adds the one optional call
 *          int  fs_NAME_solid(const fs_NAME *s, fs_solid *out);                         0 / -1 + fs_error
 *      (its closed 3-D pieces, written by --mesh and --asset instead of the lifted surface; a case
 *      in fs_model_solid). src/model/NAME/internal.h holds the state struct and what the model's
 *      own files (and its white-box tests) share.
 *   2. Its parameters in fs_model_setup below, its kind in fs_model_kind, a case in each switch of
 *      model.c, its preset section and keys in io/preset.c (offsets into sim's fs_config) and
 *      fissure-preset(5).
 *   3. Numerics from the shared kernels, not copies: fracture/ (principal stresses and planes, the
 *      separation tensor, candidate ranking, the event search in time, the Griffith check), geom/
 *      (mesh surgery of a crack: geom/cut.h; refinement), solve/ (CHOLMOD, CG on an operator),
 *      base/ (arrays, union-find, parallel-for that is deterministic at any thread count).
 *   4. Tests: tests/test_NAME.c for its physics, and a case in tests/test_model.c, which runs every
 *      kind through this interface on a tiny mesh.
 *
 * Dependencies point one way (STYLE.md): base <- geom <- field <- fracture/solve <- model <- sim <- cli,
 * with image below render, and render and io above model. A model includes no header of sim, render,
 * io or cli. */

/* The crack models ([preset] model). */
typedef enum { FS_MODEL_VORONOI = 0, FS_MODEL_SPRINGS, FS_MODEL_WEDGE, FS_MODEL_SHELL, FS_MODEL_TET } fs_model_kind;

/* The word of [preset] model for a kind ("voronoi", "springs", "wedge", "shell", "tet"). */
const char *fs_model_name(fs_model_kind kind);

/* Everything a model reads. Plain data; the maps' pixels are borrowed from whoever loaded them and must
 * outlive the model. */
struct fs_model_setup {
    fs_model_kind kind;
    uint64_t seed;                /* random seed: jitter, ranking ties, noise */
    fs_mesh_params mesh;          /* refinement limits (sampling itself is sim's) */
    fs_material material;
    fs_grey_map thickness_map;    /* grey-level scaling of the thickness, young's modulus and threshold */
    fs_grey_map young_map;        /* (thesis §5.9); a map without pixels scales by 1 */
    fs_grey_map threshold_map;
    fs_growth growth;
    fs_shrink shrink;
    fs_fracture_params fracture;
    fs_time_params time;
    fs_solver_params solver;
    fs_voronoi_params voronoi;
    fs_springs_params springs;
    fs_wedge_params wedge;
    fs_tet_params tet;
    fs_shell_params shell;
    double opening_scale;         /* [render] opening_scale: the surface (fs_model_surface) draws the
                                     in-plane displacement this many times over, so each crack opens
                                     as wide, along its length, as its simulated opening times it */
    double wall_slope;            /* [render] wall_slope: the share of a crack's width, in [0, 1], over
                                     which the surface draws its walls sloping down to its floor */
    const double *corner_uv;      /* mesh domain: 6 per triangle of the mesh given to fs_model_init, the
                                     texture coordinates of its corners (the UV layout the maps are
                                     rendered into; borrowed); NULL on the other domains */
};
typedef struct fs_model_setup fs_model_setup;

/* Every section at its default, the voronoi kind, seed 1, no maps. */
fs_model_setup fs_model_setup_default(void);

/* One model, whatever its kind. */
typedef struct {
    fs_model_kind kind;
    fs_mesh *mesh;                /* borrowed */
    const fs_model_setup *setup;  /* borrowed: must outlive the model */
    union {
        fs_springs *springs;
        fs_wedge_model *wedge;
        fs_tet *tet;
        fs_shell *shell;
    } state;                      /* the kind's state; voronoi has none */
} fs_model;

/* Builds the model of setup->kind on mesh (edges and rings built, as fs_delaunay leaves it) at time 0.
 * Returns 0, or -1 with fs_error (FS_ERR_DATA for parameters or a mesh the model cannot take, naming
 * the preset key; FS_ERR_INTERNAL for a solver failure); on failure nothing needs freeing. */
int fs_model_init(fs_model *m, fs_mesh *mesh, const fs_model_setup *setup);

/* Simulates from the current time to t (>= the current time; the voronoi model has no time and does
 * nothing). Returns 0, or -1 with fs_error. */
int fs_model_advance(fs_model *m, double t);

/* The texture-space surface of the current state (geom/surface.h), into out (owned by the caller,
 * empty on entry). Returns 0, or -1 with fs_error. */
int fs_model_surface(const fs_model *m, fs_surface *out);

/* Optional: the closed 3-D pieces of the current state (geom/surface.h), for models whose fragments
 * are real solids (tet); --mesh and --asset write them instead of the lifted surface. Fills out
 * (owned by the caller, empty on entry) and returns 1, or returns 0 leaving it empty for the other
 * models, or -1 with fs_error. */
int fs_model_solid(const fs_model *m, fs_solid *out);

/* Fractures and simulated time so far. */
fs_model_info fs_model_stats(const fs_model *m);

/* Logs the model's counters and timings (fs_debug, shown with --verbose). */
void fs_model_report(const fs_model *m);

/* Releases the state (not the mesh) and zeroes m. */
void fs_model_free(fs_model *m);

#endif
