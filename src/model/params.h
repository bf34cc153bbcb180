/* What the models share: settings (mesh limits, fracture, time, the equilibrium solver) and the statistics they report. */
#ifndef FS_MODEL_PARAMS_H
#define FS_MODEL_PARAMS_H

#include <stdbool.h>
#include <stdint.h>

typedef enum { FS_LATTICE_RANDOM = 0, FS_LATTICE_HEX } fs_lattice;
typedef enum { FS_FRACTURE_SPLIT = 0, FS_FRACTURE_REMOVE } fs_fracture_method;
typedef enum { FS_SOLVER_CHOLMOD = 0, FS_SOLVER_CG } fs_solver_method;
typedef enum { FS_RELAX_AUTO = 0, FS_RELAX_GLOBAL, FS_RELAX_LOCAL } fs_relax_mode;

/* [mesh]: how the domain is sampled and meshed (sim) and how far models may refine it. */
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

/* 1000 elements, random lattice, 30 repulsion iterations, radius jitter 0.2, min_size 0.05 cm, no
 * von Mises refinement (3 rounds when on), no smoothing (3 sweeps when on). */
fs_mesh_params fs_mesh_params_default(void);

/* [fracture] */
typedef struct {
    fs_fracture_method method;
    bool griffith;          /* stop cracks by the Griffith energy criterion */
    bool tip_submodel;      /* split: the stress of the tip about to extend from a refined local
                               sub-model (thesis §5.7.8) instead of the coarse estimate */
    double tip_submodel_radius; /* its radius, in mean edge lengths */
    double tip_submodel_size;   /* the size (longest edge) it refines the tip's vicinity to, in mean
                                   edge lengths */
    double direction_radius;    /* split: the radius of the stress average ahead of a tip that sets
                                   the way it runs (fs_tip_stress), in mean edge lengths; 0: the
                                   stress of the tip's most loaded element alone */
} fs_fracture_params;

/* Splitting, Griffith on, no tip sub-model (radius 4, size 0.25 when on), tip directions averaged
 * over 1.5 edge lengths. */
fs_fracture_params fs_fracture_params_default(void);

/* [time] */
typedef struct {
    double end;             /* simulated end time */
    double min_step;        /* smallest time step of the event search */
} fs_time_params;

/* End 1, min_step 1e-4. */
fs_time_params fs_time_params_default(void);

/* [solver]: how the finite element models solve for equilibrium: sparse Cholesky (factored once,
 * updated after fractures) or the thesis' conjugate gradients, kept as a baseline. */
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

/* CHOLMOD; cg tolerance 1e-8 and no iteration limit; relax auto, radius 4, tolerance 3e-2. */
fs_solver_params fs_solver_params_default(void);

/* What a model reports of its run so far (fs_model_stats). */
typedef struct {
    int64_t fractures;      /* fracture events: springs broken, elements removed, nodes split */
    double time;            /* simulated time reached */
} fs_model_info;

#endif
