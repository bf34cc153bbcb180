/* Benchmark of the engine outputs: crack graph, occlusion and sRGB-tagged PNG writing against map size.
 * Usage: bench_outputs [PRESET [SIZE...]]   (default voronoi-tile at 512 1024 2048 4096) */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/domain.h"
#include "image/image.h"
#include "io/preset.h"
#include "render/crackgraph.h"
#include "render/occlusion.h"
#include "sim/sim.h"

static int fail(void)
{
    fprintf(stderr, "bench_outputs: %s\n", fs_error_message());
    return 1;
}

int main(int argc, char **argv)
{
    const char *preset = argc > 1 ? argv[1] : "voronoi-tile";
    static const int default_sizes[] = {512, 1024, 2048, 4096};
    fs_config cfg = fs_config_default();
    char *path = fs_preset_find(preset);
    if (!path || fs_preset_load(path, &cfg) < 0)
        return fail();
    free(path);
    fs_result res;
    if (fs_sim_run(&cfg, &res) < 0)
        return fail();
    fs_domain d = cfg.domain;
    fs_domain_normalize(&d);
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    char tmp[] = "/tmp/fissure-bench-XXXXXX";
    if (!mkdtemp(tmp))
        return 1;
    char png[64];
    snprintf(png, sizeof png, "%s/b.png", tmp);
    int n_sizes = argc > 2 ? argc - 2 : 4;
    for (int s = 0; s < n_sizes; s++) {
        int size = argc > 2 ? atoi(argv[2 + s]) : default_sizes[s];
        fs_raster r;
        double t0 = fs_seconds();
        if (fs_render_raster(&res.surface, size, size, cfg.render.supersample, wu, wv, &r) < 0)
            return fail();
        double t1 = fs_seconds();
        fs_crackgraph_params cp = fs_crackgraph_params_default();
        fs_crackgraph g;
        if (fs_crackgraph_build(&r, wu, wv, &cp, &g) < 0)
            return fail();
        double t2 = fs_seconds();
        fs_occlusion_params op = fs_occlusion_params_default();
        fs_image ao;
        fs_occlusion_build(&r, &op, wu, wv, &ao);
        double t3 = fs_seconds();
        fs_maps maps;
        if (fs_maps_build(&r, &cfg.render, wu, wv, 1.0, 1.0, &maps) < 0)
            return fail();
        double t4 = fs_seconds();
        if (fs_image_write_tagged(png, &maps.basecolor, FS_IMAGE_UNTAGGED) < 0)
            return fail();
        double t5 = fs_seconds();
        if (fs_image_write_tagged(png, &maps.basecolor, FS_IMAGE_SRGB) < 0)
            return fail();
        double t6 = fs_seconds();
        printf("%s %dx%d: render %.3f s, crack graph %.3f s (%d cracks, %d nodes), occlusion %.3f s, "
               "basecolor png untagged %.3f s, srgb-tagged %.3f s\n",
               preset, size, size, t1 - t0, t2 - t1, (int)g.n_edges, (int)g.n_nodes, t3 - t2, t5 - t4, t6 - t5);
        fflush(stdout);
        fs_crackgraph_free(&g);
        fs_image_free(&ao);
        fs_maps_free(&maps);
        fs_raster_free(&r);
    }
    unlink(png);
    rmdir(tmp);
    fs_result_free(&res);
    return 0;
}
