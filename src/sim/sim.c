/* The run of one configuration: sample the domain, mesh it, run the model, hand back a render mesh. */
#include "sim/sim.h"

#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "model/springs.h"
#include "model/voronoi.h"
#include "model/wedge.h"

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

int fs_sim_run(const fs_config *cfg, fs_result *out)
{
    memset(out, 0, sizeof *out);
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
        rc = fs_springs_run(&out->mesh, &cfg->springs, &cfg->material, &cfg->growth, &cfg->shrink, cfg->time.end,
                            cfg->time.min_step, cfg->preset.seed, &out->surface, &out->stats.fractures,
                            &out->stats.simulated_time);
        break;
    case FS_MODEL_WEDGE:
        rc = fs_wedge_run(cfg, &out->mesh, &out->surface, &out->stats);
        break;
    default:
        fs_error(FS_ERR_DATA, "[preset] model: the %s model is not available in this build; expected voronoi",
                 fs_model_name(cfg->preset.model));
        rc = -1;
        break;
    }
    double t3 = fs_seconds();
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
    fs_render_mesh_free(&r->surface);
    memset(r, 0, sizeof *r);
}
