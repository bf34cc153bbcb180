/* The run of one configuration: sample the domain, mesh it, run the model, hand back a render mesh. */
#include "sim/sim.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "geom/uvmesh.h"
#include "image/image.h"
#include "model/model.h"

/* Points for the mesh: particle repulsion, or the hexagonal lattice. */
static int sample_points(const fs_config *cfg, fs_points *pts)
{
    /* the wedge and shell models count triangles (wedges, faces), the tet model those of its top
     * surface: a Delaunay mesh has about two per point */
    bool triangles = cfg->preset.model == FS_MODEL_WEDGE || cfg->preset.model == FS_MODEL_TET ||
                     cfg->preset.model == FS_MODEL_SHELL;
    int32_t count = triangles ? cfg->mesh.elements / 2 : cfg->mesh.elements;
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

/* One grey-level map of [material] (thesis §5.9), wrapping where the domain does; none for "". */
static int load_map(const char *path, const fs_domain *d, fs_grey_map *m)
{
    memset(m, 0, sizeof *m);
    if (!path[0])
        return 0;
    if (fs_image_read_grey(path, &m->width, &m->height, &m->grey) < 0)
        return -1;
    m->wrap_u = fs_domain_wraps_u(d);
    m->wrap_v = fs_domain_wraps_v(d);
    return 0;
}

static void free_maps(fs_model_setup *setup)
{
    fs_grey_map_free(&setup->thickness_map);
    fs_grey_map_free(&setup->young_map);
    fs_grey_map_free(&setup->threshold_map);
}

/* design: the one time loop of every model (model/model.h). A run without frames is the loop with one
 * frame at time.end that hands its surface to out->surface alone. */
static int run_model(const fs_config *cfg, const fs_domain *domain, const double *corner_uv,
                     const fs_sim_frames *frames, fs_result *out)
{
    fs_model_setup setup = fs_config_model_setup(cfg);
    setup.corner_uv = corner_uv;
    const fs_material_files *files = &cfg->material_files;
    if (load_map(files->thickness_map, domain, &setup.thickness_map) < 0 ||
        load_map(files->young_map, domain, &setup.young_map) < 0 ||
        load_map(files->threshold_map, domain, &setup.threshold_map) < 0) {
        free_maps(&setup);
        return -1;
    }
    fs_progress("model", -1, "%s model on %d nodes", fs_model_name(setup.kind), (int)out->mesh.n_nodes);
    fs_model model;
    int rc = fs_model_init(&model, &out->mesh, &setup);
    int32_t count = frames ? frames->count : 1;
    for (int32_t k = 1; rc == 0 && k <= count; k++) {
        double t = frame_time(cfg, k, count);
        fs_progress_scale(cfg->time.end > 0.0 ? t / cfg->time.end : 1.0);
        if ((rc = fs_model_advance(&model, t)) < 0)
            break;
        fs_progress("surface", -1, "%s model at t = %.4g", fs_model_name(setup.kind), t);
        fs_surface frame = {0};
        fs_surface *surface = k == count ? &out->surface : &frame;
        rc = fs_model_surface(&model, surface);
        if (rc == 0 && k == count && fs_model_solid(&model, &out->solid) < 0)
            rc = -1;
        fs_model_info info = fs_model_stats(&model);
        out->stats.fractures = info.fractures;
        out->stats.simulated_time = info.time;
        if (rc == 0 && frames)
            rc = frames->fn(frames->ctx, k, count, t, surface, &out->stats);
        fs_surface_free(&frame);
    }
    if (rc == 0)
        fs_model_report(&model);
    fs_model_free(&model);
    free_maps(&setup);
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
        fs_error(FS_ERR_DATA, "time-lapse frames: the voronoi model has no time; expected a springs, wedge, tet or shell "
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
    double *corner_uv = NULL;
    double t0 = fs_seconds(), t1 = t0;
    int rc;
    if (domain.type == FS_DOMAIN_MESH) {
        /* the user's mesh, checked before anything is simulated */
        fs_progress("mesh", -1, "reading %s", cfg->domain_file);
        if (fs_uvmesh_read(cfg->domain_file, &out->mesh, &corner_uv) < 0)
            return -1;
        domain = out->mesh.domain;
        fs_debug("read %d vertices, %d triangles", (int)out->mesh.n_nodes, (int)out->mesh.n_tris);
    } else {
        fs_progress("sample", -1, "%d points on the %s", (int)cfg->mesh.elements, fs_domain_type_name(domain.type));
        fs_points pts = {0};
        if (sample_points(cfg, &pts) < 0)
            return -1;
        t1 = fs_seconds();
        fs_debug("sampled %d points in %.2f s", (int)pts.n, t1 - t0);
        fs_progress("mesh", -1, "Delaunay triangulation of %d points", (int)pts.n);
        rc = fs_delaunay(&domain, &pts, &out->mesh);
        fs_points_free(&pts);
        if (rc < 0)
            return -1;
    }
    double t2 = fs_seconds();
    fs_debug("meshed %d nodes, %d triangles in %.2f s", (int)out->mesh.n_nodes, (int)out->mesh.n_tris, t2 - t1);

    out->stats.extent_u = fs_domain_extent_x(&domain);
    out->stats.extent_v = fs_domain_extent_y(&domain);
    rc = run_model(cfg, &domain, corner_uv, segmented ? frames : NULL, out);
    free(corner_uv);
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
    fs_solid_free(&r->solid);
    memset(r, 0, sizeof *r);
}
