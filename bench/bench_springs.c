/* Benchmark of the springs model: bench_springs N [MAX_BREAKS] times a mud-springs-like run of N masses. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/vec.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "model/springs/internal.h"

/* Mean spacing of the masses (cm): the tile grows with N so that the physics per mass stays that of
 * presets/mud-springs.ini (3000 masses on a 10 cm tile). */
#define BENCH_SPACING 0.196

static void usage(void)
{
    fprintf(stderr, "usage: bench_springs N [MAX_BREAKS]\n"
                    "  runs the mud-springs physics on a periodic tile of N masses about %g cm apart (stopping\n"
                    "  after MAX_BREAKS breaks if given) and prints one line of timings: meshing, simulation,\n"
                    "  seconds per break, 3-D post-process and render mesh, total.\n",
            BENCH_SPACING);
}

static int parse_count(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static fs_pwl ramp(double v_end)
{
    fs_pwl f;
    memset(&f, 0, sizeof f);
    f.n = 2;
    f.t[1] = 1.0;
    f.v[1] = v_end;
    return f;
}

int main(int argc, char **argv)
{
    long n = 0, max_breaks = 0;
    if (argc < 2 || argc > 3 || parse_count(argv[1], 16, 20000000, &n) < 0 ||
        (argc == 3 && parse_count(argv[2], 0, 2000000000, &max_breaks) < 0)) {
        usage();
        return 64;
    }
    fs_log_set_level(FS_LOG_QUIET);
    double side = sqrt(0.5 * sqrt(3.0) * (double)n) * BENCH_SPACING;
    fs_domain d = fs_domain_default();
    d.width = d.height = side;
    d.periodic_x = d.periodic_y = true;
    fs_domain_normalize(&d);

    double t0 = fs_seconds();
    fs_sample_params sp = fs_sample_params_default();
    sp.count = (int32_t)n;
    fs_points pts = {0};
    fs_mesh m = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0 || fs_delaunay(&d, &pts, &m) < 0) {
        fprintf(stderr, "bench_springs: %s\n", fs_error_message());
        return 70;
    }
    fs_points_free(&pts);
    double t1 = fs_seconds();

    fs_model_setup st = fs_model_setup_default();
    st.kind = FS_MODEL_SPRINGS;
    st.springs = fs_springs_params_default();
    st.springs.shear_lag = 2.0;
    st.springs.slide_length = 0.03;
    st.springs.residual = 0.01;
    st.springs.max_breaks = (int)max_breaks;
    st.material = fs_material_default();
    st.material.young = 10.0;
    st.material.threshold = 100.0;
    st.material.thickness = 0.3;
    st.material.jitter = 0.03;
    st.growth = fs_growth_default();
    st.shrink = fs_shrink_default();
    st.shrink.top = ramp(0.09);
    st.shrink.bottom = ramp(0.05);
    st.time.end = 1.0;
    st.time.min_step = 1e-3;
    st.seed = 1;

    fs_springs s;
    fs_surface r = {0};
    int rc = fs_springs_init(&s, &m, &st);
    if (rc == 0)
        rc = fs_springs_advance(&s, st.time.end);
    double t2 = fs_seconds();
    if (rc == 0)
        rc = fs_springs_surface(&s, &r);
    double t3 = fs_seconds();
    if (rc < 0) {
        fprintf(stderr, "bench_springs: %s\n", fs_error_message());
        return 70;
    }
    printf("springs n=%ld tile=%.1fcm mesh=%.2fs simulate=%.2fs breaks=%d t=%.3g per_break=%.2fms "
           "equilibria=%lld solves=%lld factorizations=%lld post=%.2fs render_tris=%d total=%.2fs\n",
           n, side, t1 - t0, t2 - t1, (int)s.break_count, s.time,
           s.break_count ? 1e3 * (t2 - t1) / s.break_count : 0.0, (long long)s.evaluations, (long long)s.net.solves,
           (long long)s.net.factorizations, t3 - t2, (int)r.n_tris, t3 - t0);
    fs_surface_free(&r);
    fs_springs_free(&s);
    fs_mesh_free(&m);
    return 0;
}
