/* The run of one configuration: domain, sampling, mesh, model, time loop; ends with a render mesh. */
#ifndef FS_SIM_SIM_H
#define FS_SIM_SIM_H

#include <stdint.h>

#include "geom/mesh.h"
#include "geom/surface.h"
#include "sim/settings.h"

typedef struct {
    int64_t nodes;           /* nodes (or points) of the final mesh */
    int64_t elements;        /* elements (triangles, wedges, springs) of the final mesh */
    int64_t fractures;       /* fracture events */
    double simulated_time;   /* time reached */
    double sample_seconds, mesh_seconds, model_seconds; /* wall time per phase */
    double extent_u, extent_v; /* cm per unit of texture along u and v (a mesh domain's from its area) */
} fs_stats;

typedef struct {
    fs_mesh mesh;            /* the final mesh */
    fs_surface surface;  /* what the renderer draws */
    fs_solid solid;      /* the final state's closed 3-D pieces, for models that have them (empty
                            otherwise): what --mesh and --asset write */
    fs_stats stats;
} fs_result;

/* Called for time-lapse frame k (1 .. count) with the render mesh of the state at time t (borrowed,
 * valid during the call) and the statistics so far. Returns 0, or -1 with fs_error to stop the run. */
typedef int (*fs_frame_fn)(void *ctx, int32_t k, int32_t count, double t, const fs_surface *surface,
                           const fs_stats *stats);

/* Time-lapse frames (--frames): count >= 1 states at t_k = k end / count, k = 1 .. count. */
typedef struct {
    int32_t count;
    fs_frame_fn fn;
    void *ctx;
} fs_sim_frames;

/* Runs cfg to completion. Returns 0, or -1 with fs_error. The result is owned by the caller. */
int fs_sim_run(const fs_config *cfg, fs_result *out);

/* As fs_sim_run, and hands frames->fn the state at each frame time (the last one is the final state,
 * out->surface). frames may be NULL (no frames).
 * design: the physical models run in segments, [t_(k-1), t_k], each advanced again from where it
 * stopped (fs_model_advance); an event search that would have
 * stepped over t_k stops there instead, so the pattern can differ slightly from a run without
 * frames (it is still deterministic for a given seed and frame count). The voronoi model has no
 * time: frames of it are an error (FS_ERR_DATA; the CLI reports it as a usage error first). */
int fs_sim_run_frames(const fs_config *cfg, const fs_sim_frames *frames, fs_result *out);
void fs_result_free(fs_result *r);

#endif
