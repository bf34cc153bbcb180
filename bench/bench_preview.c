/* Benchmark of the 3-D outputs: lifting the render mesh, writing it as OBJ, and the lit preview.
 * Usage: bench_preview [PRESET [PREVIEW_WxH]]   (default voronoi-tile, 1024x768; maps 1024x1024) */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/domain.h"
#include "io/obj.h"
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
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    fs_raster raster;
    fs_maps maps;
    if (fs_render_raster(&res.surface, cfg.render.width, cfg.render.height, cfg.render.supersample, wu, wv,
                         &raster) < 0 ||
        fs_maps_build(&raster, &cfg.render, wu, wv, fs_domain_extent_x(&d) / cfg.render.width,
                      fs_domain_extent_y(&d) / cfg.render.height, &maps) < 0)
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
    fs_image preview;
    if (fs_render_preview(&res.surface, &d, &cfg.render, &maps, &preview) < 0)
        return fail();
    double t3 = fs_seconds();
    printf("preset=%s render_tris=%d lifted_tris=%d positions=%d lift_s=%.3f obj_s=%.3f preview=%dx%d preview_s=%.3f\n",
           preset, (int)res.surface.n_tris, (int)l.n_tris, (int)l.n_pos, t1 - t0, t2 - t1, cfg.render.preview_width,
           cfg.render.preview_height, t3 - t2);
    unlink(obj);
    rmdir(tmp);
    fs_image_free(&preview);
    fs_lifted_mesh_free(&l);
    fs_maps_free(&maps);
    fs_raster_free(&raster);
    fs_result_free(&res);
    return 0;
}
