/* Benchmark of the 3-D outputs: lifting the render mesh, writing it as OBJ, and the lit preview.
 * Usage: bench_preview [PRESET [PREVIEW_WxH]]   (default voronoi-tile, 1024x768; maps 1024x1024) */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/domain.h"
#include "io/obj.h"
#include "io/outputs.h"
#include "io/preset.h"
#include "render/render.h"
#include "sim/sim.h"

static int fail(void)
{
    fprintf(stderr, "bench_preview: %s\n", fs_error_message());
    return 1;
}

int main(int argc, char **argv)
{
    const char *preset = argc > 1 ? argv[1] : "voronoi-tile";
    fs_config cfg = fs_config_default();
    char *path = fs_preset_find(preset);
    if (!path || fs_preset_load(path, &cfg) < 0)
        return fail();
    free(path);
    cfg.render.width = cfg.render.height = 1024;
    if (argc > 2) {
        char set[64];
        snprintf(set, sizeof set, "render.preview_size=%s", argv[2]);
        if (fs_preset_set(&cfg, set) < 0)
            return fail();
    }
    fs_result res;
    if (fs_sim_run(&cfg, &res) < 0)
        return fail();
    fs_domain d = cfg.domain;
    fs_domain_normalize(&d);
    bool kinds[FS_MAP_COUNT] = {[FS_MAP_PREVIEW] = true};
    fs_outputs built;
    if (fs_outputs_build(&res.surface, &cfg, kinds, false, &built) < 0)
        return fail();

    double t0 = fs_seconds();
    fs_lifted_mesh l;
    if (fs_render_lift(&res.surface, &d, 1.0, &l) < 0)
        return fail();
    double t1 = fs_seconds();
    char tmp[] = "/tmp/fissure-bench-XXXXXX";
    if (!mkdtemp(tmp))
        return 1;
    char obj[64];
    snprintf(obj, sizeof obj, "%s/mesh.obj", tmp);
    if (fs_obj_write(obj, &l, "bench", NULL, NULL) < 0)
        return fail();
    double t2 = fs_seconds();
    printf("preset=%s render_tris=%d lifted_tris=%d positions=%d lift_s=%.3f obj_s=%.3f preview=%dx%d preview_s=%.3f\n",
           preset, (int)res.surface.n_tris, (int)l.n_tris, (int)l.n_pos, t1 - t0, t2 - t1, cfg.render.preview_width,
           cfg.render.preview_height, built.preview_seconds);
    unlink(obj);
    rmdir(tmp);
    fs_lifted_mesh_free(&l);
    fs_outputs_free(&built);
    fs_result_free(&res);
    return 0;
}
