/* The run of one configuration: domain, sampling, mesh, model, time loop; ends with a render mesh. */
#ifndef FS_SIM_SIM_H
#define FS_SIM_SIM_H

#include <stdint.h>

#include "geom/mesh.h"
#include "render/render.h"
#include "sim/config.h"

typedef struct {
    int64_t nodes;           /* nodes (or points) of the final mesh */
    int64_t elements;        /* elements (triangles, wedges, springs) of the final mesh */
    int64_t fractures;       /* fracture events */
    double simulated_time;   /* time reached */
    double sample_seconds, mesh_seconds, model_seconds; /* wall time per phase */
} fs_stats;

typedef struct {
    fs_mesh mesh;            /* the final mesh */
    fs_render_mesh surface;  /* what the renderer draws */
    fs_stats stats;
} fs_result;

/* Runs cfg to completion. Returns 0, or -1 with fs_error. The result is owned by the caller. */
int fs_sim_run(const fs_config *cfg, fs_result *out);
void fs_result_free(fs_result *r);

#endif
