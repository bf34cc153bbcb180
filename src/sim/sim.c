/* The run of one configuration: sample the domain, mesh it, run the model, hand back a render mesh. */
#include "sim/sim.h"

#include <stdbool.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "model/springs/springs.h"
#include "model/voronoi.h"
#include "model/wedge/wedge.h"

/* Points for the mesh: particle repulsion, or the hexagonal lattice. */
static int sample_points(const fs_config *cfg, fs_points *pts)
{
    /* the wedge model counts triangles (wedges): a Delaunay mesh has about two per point */
    int32_t count = cfg->preset.model == FS_MODEL_WEDGE ? cfg->mesh.elements / 2 : cfg->mesh.elements;
    if (cfg->mesh.lattice == FS_LATTICE_HEX)
        return fs_sample_hex(&cfg->domain, count, pts);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = count;
    sp.iterations = cfg->mesh.relax_iterations;
    sp.radius_jitter = cfg->mesh.radius_jitter;
    sp.seed = cfg->preset.seed;
    return fs_sample_repulsion(&cfg->domain, &sp, pts);
}

/* Time of frame k of count over [0, end]; the last one is exactly end. */
static double frame_time(const fs_config *cfg, int32_t k, int32_t count)
{
    return k == count ? cfg->time.end : cfg->time.end * (double)k / (double)count;
}

/* The springs model in segments: init, advance to each frame time, render each frame. */
static int run_springs_frames(const fs_config *cfg, const fs_sim_frames *frames, fs_result *out)
{
    fs_springs_setup setup;
    memset(&setup, 0, sizeof setup);
    setup.springs = cfg->springs;
    setup.material = cfg->material;
    setup.growth = cfg->growth;
    setup.shrink = cfg->shrink;
    setup.time_end = cfg->time.end;
    setup.min_step = cfg->time.min_step;
    setup.seed = cfg->preset.seed;
    fs_springs s;
    int rc = fs_springs_init(&s, &out->mesh, &setup);
    for (int32_t k = 1; rc == 0 && k <= frames->count; k++) {
        double t = frame_time(cfg, k, frames->count);
        fs_progress_scale(cfg->time.end > 0.0 ? t / cfg->time.end : 1.0);
        rc = fs_springs_advance(&s, t);
        if (rc < 0)
            break;
        fs_progress("springs", -1, "frame %d of %d: 3-D post-process of %d cells", (int)k, (int)frames->count,
                    (int)out->mesh.n_nodes);
        fs_surface frame = {0};
        fs_surface *surface = k == frames->count ? &out->surface : &frame;
        rc = fs_springs_render(&s, surface);
        out->stats.fractures = s.break_count;
        out->stats.simulated_time = s.time;
        if (rc == 0)
            rc = frames->fn(frames->ctx, k, frames->count, t, surface, &out->stats);
        fs_surface_free(&frame);
    }
    fs_springs_free(&s);
    return rc;
}

/* The wedge model in segments: init, simulate to each frame time, render each frame. */
static int run_wedge_frames(const fs_config *cfg, const fs_sim_frames *frames, fs_result *out)
{
    fs_wedge_model w;
    if (fs_wedge_init(&w, &out->mesh, cfg) < 0)
        return -1;
    int rc = 0;
    for (int32_t k = 1; rc == 0 && k <= frames->count; k++) {
        double t = frame_time(cfg, k, frames->count);
        fs_progress_scale(cfg->time.end > 0.0 ? t / cfg->time.end : 1.0);
        rc = fs_wedge_simulate(&w, t);
        if (rc < 0)
            break;
        fs_surface frame = {0};
        fs_surface *surface = k == frames->count ? &out->surface : &frame;
        rc = fs_wedge_render_mesh(&w, surface);
        out->stats.fractures = w.fractures;
        out->stats.simulated_time = w.time;
        out->stats.elements = w.n_elems;
        if (rc == 0)
            rc = frames->fn(frames->ctx, k, frames->count, t, surface, &out->stats);
        fs_surface_free(&frame);
    }
    fs_wedge_free(&w);
    return rc;
}

int fs_sim_run(const fs_config *cfg, fs_result *out)
{
    return fs_sim_run_frames(cfg, NULL, out);
}

int fs_sim_run_frames(const fs_config *cfg, const fs_sim_frames *frames, fs_result *out)
{
    memset(out, 0, sizeof *out);
    if (frames && frames->count > 0 && cfg->preset.model == FS_MODEL_VORONOI) {
        fs_error(FS_ERR_DATA, "time-lapse frames: the voronoi model has no time; expected a springs or wedge "
                 "model");
        return -1;
    }
    if (frames && frames->count > 0 && !frames->fn) {
        fs_error(FS_ERR_INTERNAL, "frames requested without a frame callback");
        return -1;
    }
    bool segmented = frames && frames->count > 0;
    fs_domain domain = cfg->domain;
    fs_domain_normalize(&domain);

    double t0 = fs_seconds();
    fs_progress("sample", -1, "%d points on the %s", (int)cfg->mesh.elements, fs_domain_type_name(domain.type));
    fs_points pts = {0};
    if (sample_points(cfg, &pts) < 0)
        return -1;
    double t1 = fs_seconds();
    fs_debug("sampled %d points in %.2f s", (int)pts.n, t1 - t0);

    fs_progress("mesh", -1, "Delaunay triangulation of %d points", (int)pts.n);
    int rc = fs_delaunay(&domain, &pts, &out->mesh);
    fs_points_free(&pts);
    if (rc < 0)
        return -1;
    double t2 = fs_seconds();
    fs_debug("meshed %d nodes, %d triangles in %.2f s", (int)out->mesh.n_nodes, (int)out->mesh.n_tris, t2 - t1);

    switch (cfg->preset.model) {
    case FS_MODEL_VORONOI:
        fs_progress("model", -1, "voronoi cells");
        rc = fs_voronoi_render_mesh(&out->mesh, &cfg->voronoi, cfg->preset.seed, &out->surface);
        break;
    case FS_MODEL_SPRINGS:
        if (segmented) {
            rc = run_springs_frames(cfg, frames, out);
            break;
        }
        rc = fs_springs_run(&out->mesh, &cfg->springs, &cfg->material, &cfg->growth, &cfg->shrink, cfg->time.end,
                            cfg->time.min_step, cfg->preset.seed, &out->surface, &out->stats.fractures,
                            &out->stats.simulated_time);
        break;
    case FS_MODEL_WEDGE:
        rc = segmented ? run_wedge_frames(cfg, frames, out) : fs_wedge_run(cfg, &out->mesh, &out->surface, &out->stats);
        break;
    default:
        fs_error(FS_ERR_DATA, "[preset] model: the %s model is not available in this build; expected voronoi",
                 fs_model_name(cfg->preset.model));
        rc = -1;
        break;
    }
    double t3 = fs_seconds();
    fs_progress_scale(1.0);
    fs_progress_done();
    if (rc < 0) {
        fs_result_free(out);
        return -1;
    }
    out->stats.nodes = out->mesh.n_nodes;
    out->stats.elements = out->mesh.n_tris;
    out->stats.sample_seconds = t1 - t0;
    out->stats.mesh_seconds = t2 - t1;
    out->stats.model_seconds = t3 - t2;
    return 0;
}

void fs_result_free(fs_result *r)
{
    fs_mesh_free(&r->mesh);
    fs_surface_free(&r->surface);
    memset(r, 0, sizeof *r);
}
