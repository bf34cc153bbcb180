/* The resolved configuration of one run: what a preset (plus overrides) becomes, section by section. */
#ifndef FS_SIM_SETTINGS_H
#define FS_SIM_SETTINGS_H

#include <stdbool.h>
#include <stdint.h>

#include "field/field.h"
#include "geom/domain.h"
#include "model/springs/springs.h"
#include "model/voronoi.h"
#include "render/render.h"

typedef enum { FS_MODEL_VORONOI = 0, FS_MODEL_SPRINGS, FS_MODEL_WEDGE, FS_MODEL_SHELL, FS_MODEL_TET } fs_model_type;
typedef enum { FS_LATTICE_RANDOM = 0, FS_LATTICE_HEX } fs_lattice;
typedef enum { FS_FRACTURE_SPLIT = 0, FS_FRACTURE_REMOVE } fs_fracture_method;

typedef struct {
    char name[64];          /* short name, used as the default output name */
    char description[256];  /* one line shown by --list-presets */
    fs_model_type model;
    uint64_t seed;          /* random seed (the command line's --seed overrides it) */
} fs_preset_info;

typedef struct {
    int32_t elements;       /* target number of elements (voronoi: cells; springs: masses) */
    double min_size;        /* smallest element dynamic subdivision may make (cm) */
    fs_lattice lattice;     /* random (particle repulsion) or hexagonal lattice */
    int relax_iterations;   /* particle repulsion iterations */
    double radius_jitter;   /* random perturbation of the repulsion radii (relative) */
    double refine_vm;       /* wedge: adaptive refinement by von Mises discontinuity (thesis §5.7.7,
                               Algorithm 13) at every new time step: the threshold of a node's
                               (max - min von Mises of its elements) / largest principal stress;
                               0 = off */
    int refine_vm_rounds;   /* wedge: refinement rounds (subdivide once, re-solve) per time step */
    double smooth_radius;   /* wedge, split: angle-based smoothing of the nodes within this many mean
                               edge lengths of every new crack tip (thesis §5.7.9); 0 = off */
    int smooth_iterations;  /* wedge, split: smoothing sweeps over those nodes per new tip */
} fs_mesh_params;

typedef struct {
    fs_fracture_method method;
    bool griffith;          /* stop cracks by the Griffith energy criterion */
    bool tip_submodel;      /* split: the stress of the tip about to extend from a refined local
                               sub-model (thesis §5.7.8) instead of the coarse estimate */
    double tip_submodel_radius; /* its radius, in mean edge lengths */
    double tip_submodel_size;   /* the size (longest edge) it refines the tip's vicinity to, in mean
                                   edge lengths */
} fs_fracture_params;

typedef struct {
    double end;             /* simulated end time */
    double min_step;        /* smallest time step of the event search */
} fs_time_params;

typedef enum { FS_SOLVER_CHOLMOD = 0, FS_SOLVER_CG } fs_solver_method;
typedef enum { FS_RELAX_AUTO = 0, FS_RELAX_GLOBAL, FS_RELAX_LOCAL } fs_relax_mode;

/* How the finite element models solve for equilibrium: sparse Cholesky (factored once, updated after
 * fractures) or the thesis' conjugate gradients, kept as a baseline. */
typedef struct {
    fs_solver_method method;
    double tolerance;       /* cg: relative residual ||b - Ax|| / ||b|| to stop at */
    int32_t max_iterations; /* cg: iteration limit, 0 for the number of unknowns */
    fs_relax_mode relax;    /* after a local change (a fracture): relax the whole model, or first
                               only the nodes around the change (thesis §5.8); auto: local
                               (faster for both fracture methods, the same patterns) */
    double relax_radius;    /* local: initial radius of the relaxed region, in mean edge lengths */
    double relax_tolerance; /* local: a local relaxation is accepted when no residual entry of
                               f - K u exceeds relax_tolerance times the root mean square of f */
} fs_solver_params;

/* Wedge model settings that have no section of their own. */
typedef struct {
    double thickness_gradient; /* relative change of the thickness across the texture in u: the
                                  thickness is scaled by 1 + gradient (u - 1/2) */
} fs_wedge_params;

typedef struct {
    fs_preset_info preset;
    fs_domain domain;
    fs_mesh_params mesh;
    fs_material material;
    fs_growth growth;
    fs_shrink shrink;
    fs_fracture_params fracture;
    fs_time_params time;
    fs_render_params render;
    fs_voronoi_params voronoi;
    fs_springs_params springs;
    fs_solver_params solver;
    fs_wedge_params wedge;
} fs_config;

/* Every section at its default: a 10 x 10 cm non-periodic plane, voronoi model, 1000 elements. */
fs_config fs_config_default(void);

const char *fs_model_name(fs_model_type m);

#endif
