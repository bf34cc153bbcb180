/* Tests of the model interface (model/model.h): every kind through init, advance, surface, stats and free on a tiny mesh, and sim's one time loop with its frames. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "check.h"
#include "mesh_fixture.h"
#include "model/model.h"
#include "sim/sim.h"

/* A thin layer that shrinks on top while its bottom holds: it must crack, whatever the model. */
static fs_model_setup shrinking_layer(fs_model_kind kind)
{
    fs_model_setup s = fs_model_setup_default();
    s.kind = kind;
    s.seed = 9;
    s.material.young = 10.0;
    s.material.threshold = 100.0;
    s.material.thickness = 0.2;
    s.material.jitter = 0.1;
    s.shrink.top.n = s.shrink.bottom.n = 2;
    s.shrink.top.t[1] = s.shrink.bottom.t[1] = 1.0;
    s.shrink.top.v[1] = 0.05;
    s.shrink.bottom.v[1] = 0.0;
    s.time.end = 1.0;
    s.time.min_step = 1e-3;
    s.mesh.min_size = 1e3; /* no subdivision: a small, quick run */
    return s;
}

/* The facts every surface must have: finite heights, texture coordinates near the unit square (less
 * than a period outside), cell ids that are small non-negative integers, valid triangles. */
static void check_surface(const fs_surface *s, const char *what)
{
    CHECK_MSG(s->n_tris > 0 && s->n_verts > 0, "%s: empty surface", what);
    int bad = 0;
    for (int32_t v = 0; v < s->n_verts; v++) {
        float u = s->uv[2 * v], w = s->uv[2 * v + 1];
        bad += !isfinite(s->height[v]) || !(u > -1.0f && u < 2.0f && w > -1.0f && w < 2.0f) ||
               !(s->cell[v] >= 0.0f && s->cell[v] <= 65535.0f && s->cell[v] == floorf(s->cell[v])) ||
               !(s->crack[v] >= 0.0f && s->crack[v] <= 1.0f);
    }
    for (int32_t k = 0; k < 3 * s->n_tris; k++)
        bad += s->tri[k] < 0 || s->tri[k] >= s->n_verts;
    CHECK_MSG(bad == 0, "%s: %d bad vertices or corners", what, bad);
}

/* Voronoi has no time: advance does nothing, the surface has one cell per node and no fracture. */
static void test_voronoi(void)
{
    fs_mesh m = {0};
    CHECK(sampled_tile(4.0, 60, 5, &m) == 0);
    fs_model_setup s = fs_model_setup_default();
    fs_model model;
    CHECK(fs_model_init(&model, &m, &s) == 0);
    CHECK(fs_model_advance(&model, 5.0) == 0);
    fs_surface surf = {0};
    CHECK(fs_model_surface(&model, &surf) == 0);
    check_surface(&surf, "voronoi");
    float cells = 0.0f;
    for (int32_t v = 0; v < surf.n_verts; v++)
        cells = fmaxf(cells, surf.cell[v]);
    CHECK_MSG((int32_t)cells == m.n_nodes, "largest cell id %g, %d nodes", cells, (int)m.n_nodes);
    fs_model_info info = fs_model_stats(&model);
    CHECK(info.fractures == 0 && info.time == 0.0);
    fs_model_report(&model);
    fs_model_free(&model);
    CHECK(model.kind == FS_MODEL_VORONOI && model.mesh == NULL);
    fs_surface_free(&surf);
    fs_mesh_free(&m);
}

/* Each physical model cracks the shrinking layer, reaches the times it is advanced to in two steps,
 * never loses a fracture between them, and draws a valid surface with more than one fragment. */
static void run_physical(fs_model_kind kind, fs_fracture_method method)
{
    const char *name = fs_model_name(kind);
    fs_mesh m = {0};
    CHECK(sampled_tile(4.0, kind == FS_MODEL_SPRINGS ? 300 : 150, 5, &m) == 0);
    fs_model_setup s = shrinking_layer(kind);
    s.fracture.method = method;
    fs_model model;
    CHECK_MSG(fs_model_init(&model, &m, &s) == 0, "%s: %s", name, fs_error_message());
    CHECK(fs_model_advance(&model, 0.5) == 0);
    fs_model_info half = fs_model_stats(&model);
    CHECK_MSG(fabs(half.time - 0.5) < 1e-12, "%s: time %g after advancing to 0.5", name, half.time);
    CHECK_MSG(fs_model_advance(&model, 1.0) == 0, "%s: %s", name, fs_error_message());
    fs_model_info end = fs_model_stats(&model);
    CHECK_MSG(fabs(end.time - 1.0) < 1e-12, "%s: time %g after advancing to 1", name, end.time);
    CHECK_MSG(end.fractures > 0 && end.fractures >= half.fractures, "%s: %lld then %lld fractures", name,
              (long long)half.fractures, (long long)end.fractures);
    fs_surface surf = {0};
    CHECK(fs_model_surface(&model, &surf) == 0);
    check_surface(&surf, name);
    int cracked = 0;
    float cells = 0.0f;
    for (int32_t v = 0; v < surf.n_verts; v++) {
        cracked += surf.crack[v] > 0.5f;
        cells = fmaxf(cells, surf.cell[v]);
    }
    CHECK_MSG(cracked > 0 && cells >= 2.0f, "%s: %d crack vertices, largest cell id %g", name, cracked, cells);
    fs_model_report(&model);
    fs_model_free(&model);
    fs_surface_free(&surf);
    fs_mesh_free(&m);
}

static void test_springs(void) { run_physical(FS_MODEL_SPRINGS, FS_FRACTURE_SPLIT); }
static void test_wedge_split(void) { run_physical(FS_MODEL_WEDGE, FS_FRACTURE_SPLIT); }
static void test_wedge_remove(void) { run_physical(FS_MODEL_WEDGE, FS_FRACTURE_REMOVE); }
static void test_tet(void) { run_physical(FS_MODEL_TET, FS_FRACTURE_SPLIT); }
static void test_shell(void) { run_physical(FS_MODEL_SHELL, FS_FRACTURE_SPLIT); }

/* An unknown kind and bad parameters fail cleanly, with a data error naming the model or the key. */
static void test_refusals(void)
{
    fs_mesh m = {0};
    CHECK(sampled_tile(4.0, 60, 5, &m) == 0);
    {
        fs_model_setup s = shrinking_layer(FS_MODEL_WEDGE);
        s.kind = (fs_model_kind)99;
        fs_model model;
        fs_error_clear();
        CHECK(fs_model_init(&model, &m, &s) == -1);
        CHECK(fs_error_domain() == FS_ERR_DATA && strstr(fs_error_message(), "[preset] model"));
    }
    fs_model_setup s = shrinking_layer(FS_MODEL_WEDGE);
    s.material.young = -1.0;
    fs_model model;
    CHECK(fs_model_init(&model, &m, &s) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA && strstr(fs_error_message(), "young"));
    s = shrinking_layer(FS_MODEL_SPRINGS);
    s.springs.layers = 0;
    CHECK(fs_model_init(&model, &m, &s) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA && strstr(fs_error_message(), "layers"));
    fs_mesh_free(&m);
}

/* sim's loop: frames come in order at k end / count, the last one is the final surface, statistics
 * follow, and the result has the final mesh's counts. */
typedef struct {
    int calls;
    double last_t;
    int32_t last_tris;
    int64_t last_fractures;
    bool ordered;
} frame_log;

static int on_frame(void *ctx, int32_t k, int32_t count, double t, const fs_surface *surface, const fs_stats *stats)
{
    frame_log *f = ctx;
    f->ordered = f->ordered && k == f->calls + 1 && fabs(t - (double)k / (double)count * 0.5) < 1e-12 &&
                 t > f->last_t && stats->fractures >= f->last_fractures;
    f->calls++;
    f->last_t = t;
    f->last_tris = surface->n_tris;
    f->last_fractures = stats->fractures;
    return 0;
}

static int fail_frame(void *ctx, int32_t k, int32_t count, double t, const fs_surface *surface, const fs_stats *stats)
{
    (void)ctx, (void)k, (void)count, (void)t, (void)surface, (void)stats;
    fs_error(FS_ERR_IO, "frame writer failed");
    return -1;
}

static fs_config small_run(fs_model_kind kind)
{
    fs_config c = fs_config_default();
    c.preset.model = kind;
    c.preset.seed = 4;
    c.domain.width = c.domain.height = 4.0;
    c.domain.periodic_x = c.domain.periodic_y = true;
    c.mesh.elements = 300;
    c.material.young = 10.0;
    c.material.threshold = 100.0;
    c.material.thickness = 0.2;
    c.shrink.top.n = 2;
    c.shrink.top.t[1] = 1.0;
    c.shrink.top.v[1] = 0.05;
    c.time.end = 0.5;
    c.time.min_step = 1e-3;
    c.mesh.min_size = 1e3; /* no subdivision: a small, quick run */
    return c;
}

static void test_sim_frames(void)
{
    fs_config c = small_run(FS_MODEL_SPRINGS);
    frame_log log = {.ordered = true};
    fs_sim_frames frames = {3, on_frame, &log};
    fs_result r;
    CHECK_MSG(fs_sim_run_frames(&c, &frames, &r) == 0, "%s", fs_error_message());
    CHECK(log.calls == 3 && log.ordered);
    CHECK(log.last_tris == r.surface.n_tris && log.last_fractures == r.stats.fractures);
    CHECK(r.stats.simulated_time == 0.5 && r.stats.fractures > 0);
    CHECK(r.stats.nodes == r.mesh.n_nodes && r.stats.elements == r.mesh.n_tris);
    fs_result_free(&r);

    /* a frame writer's failure stops the run with its error */
    frames.fn = fail_frame;
    CHECK(fs_sim_run_frames(&c, &frames, &r) == -1 && fs_error_domain() == FS_ERR_IO);

    /* voronoi has no time to show frames of */
    c = small_run(FS_MODEL_VORONOI);
    frames.fn = on_frame;
    CHECK(fs_sim_run_frames(&c, &frames, &r) == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK(fs_sim_run(&c, &r) == 0 && r.stats.fractures == 0 && r.surface.n_tris > 0);
    fs_result_free(&r);
}

/* A run without frames is the loop with one frame at the end: the same result as one frame. */
static void test_sim_one_frame(void)
{
    fs_config c = small_run(FS_MODEL_WEDGE);
    fs_result a, b;
    frame_log log = {.ordered = true};
    fs_sim_frames one = {1, on_frame, &log};
    CHECK(fs_sim_run(&c, &a) == 0);
    CHECK(fs_sim_run_frames(&c, &one, &b) == 0);
    CHECK(log.calls == 1 && a.stats.fractures == b.stats.fractures && a.surface.n_tris == b.surface.n_tris &&
          a.surface.n_verts == b.surface.n_verts);
    CHECK(a.surface.n_verts == b.surface.n_verts &&
          !memcmp(a.surface.uv, b.surface.uv, 2 * (size_t)a.surface.n_verts * sizeof *a.surface.uv));
    fs_result_free(&a);
    fs_result_free(&b);
}

/* A missing map image stops the run before the model, as missing input. */
static void test_sim_missing_map(void)
{
    fs_config c = small_run(FS_MODEL_WEDGE);
    snprintf(c.material_files.threshold_map, sizeof c.material_files.threshold_map, "%s",
             "/nonexistent/threshold.png");
    fs_result r;
    CHECK(fs_sim_run(&c, &r) == -1);
    CHECK(fs_error_domain() == FS_ERR_NOINPUT && strstr(fs_error_message(), "/nonexistent/threshold.png"));
}

int main(void)
{
    fs_log_set_level(FS_LOG_QUIET);
    RUN(test_voronoi);
    RUN(test_springs);
    RUN(test_wedge_split);
    RUN(test_wedge_remove);
    RUN(test_tet);
    RUN(test_shell);
    RUN(test_refusals);
    RUN(test_sim_frames);
    RUN(test_sim_one_frame);
    RUN(test_sim_missing_map);
    return check_finish();
}
