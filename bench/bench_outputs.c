/* Benchmark of the engine outputs: crack graph, occlusion and sRGB-tagged PNG writing against map size.
 * Usage: bench_outputs [PRESET [SIZE...]]   (default voronoi-tile at 512 1024 2048 4096) */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "base/error.h"
#include "base/log.h"
#include "image/image.h"
#include "io/outputs.h"
#include "io/preset.h"
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
    char tmp[] = "/tmp/fissure-bench-XXXXXX";
    if (!mkdtemp(tmp))
        return 1;
    char png[64];
    snprintf(png, sizeof png, "%s/b.png", tmp);
    int n_sizes = argc > 2 ? argc - 2 : 4;
    for (int s = 0; s < n_sizes; s++) {
        int size = argc > 2 ? atoi(argv[2 + s]) : default_sizes[s];
        cfg.render.width = cfg.render.height = size;
        bool kinds[FS_MAP_COUNT] = {[FS_MAP_OCCLUSION] = true, [FS_MAP_CRACKS] = true};
        fs_outputs b;
        if (fs_outputs_build(&res.surface, &cfg, kinds, false, &b) < 0)
            return fail();
        double t4 = fs_seconds();
        if (fs_image_write_tagged(png, &b.maps.basecolor, FS_IMAGE_UNTAGGED) < 0)
            return fail();
        double t5 = fs_seconds();
        if (fs_image_write_tagged(png, &b.maps.basecolor, FS_IMAGE_SRGB) < 0)
            return fail();
        double t6 = fs_seconds();
        printf("%s %dx%d: render %.3f s, maps %.3f s, crack graph %.3f s (%d cracks, %d nodes), occlusion %.3f s, "
               "basecolor png untagged %.3f s, srgb-tagged %.3f s\n",
               preset, size, size, b.render_seconds, b.maps_seconds, b.cracks_seconds, (int)b.cracks.n_edges,
               (int)b.cracks.n_nodes, b.occlusion_seconds, t5 - t4, t6 - t5);
        fflush(stdout);
        fs_outputs_free(&b);
    }
    unlink(png);
    rmdir(tmp);
    fs_result_free(&res);
    return 0;
}
