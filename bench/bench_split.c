/* Benchmark of wedge fracture by element splitting: the cost of one fracture event with local relaxation (thesis §5.8) against a global solve; bench_split PRESET.ini N [EVENTS]. */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/error.h"
#include "base/log.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "io/preset.h"
#include "model/wedge/internal.h"

/* CPU seconds of the process (all threads): the machine running a benchmark may be shared. */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void usage(void)
{
    fprintf(stderr, "usage: bench_split PRESET.ini N [EVENTS]\n"
                    "  builds the element-splitting wedge model of the preset with N elements, brings it to\n"
                    "  the time of its first fracture, and times EVENTS (default 40) fracture events on two\n"
                    "  copies: each event relaxed locally (thesis 5.8; the factor is left stale and global\n"
                    "  solves use CG) and each event relaxed by a global solve (the split changes the\n"
                    "  matrix's pattern: CHOLMOD analysis, factorization and solve). Prints one line: the\n"
                    "  mean wall and CPU seconds per event, the event (cut and system update) included.\n");
}

static int fail(void)
{
    fprintf(stderr, "bench_split: %s\n", fs_error_message());
    return 70;
}

/* Time of the first fracture: the earliest multiple of min_step past the largest ratio reaching 1, by
 * doubling then bisection on exact equilibria (the model is left there). */
static int first_fracture(fs_wedge_model *w, double t_end, double min_step)
{
    double lo = 0.0, hi = min_step;
    for (;;) {
        if (fs_wedge_equilibrium(w, hi) < 0)
            return -1;
        if (fs_wedge_split_max_ratio(w) > 1.0)
            break;
        if (hi >= t_end) {
            fs_error(FS_ERR_DATA, "no fracture up to the end time %g", t_end);
            return -1;
        }
        lo = hi;
        hi = hi * 2.0 > t_end ? t_end : hi * 2.0;
    }
    while (hi - lo > min_step) {
        double mid = 0.5 * (lo + hi);
        if (fs_wedge_equilibrium(w, mid) < 0)
            return -1;
        if (fs_wedge_split_max_ratio(w) > 1.0)
            hi = mid;
        else
            lo = mid;
    }
    return fs_wedge_equilibrium(w, hi);
}

/* EVENTS split events on w, each relaxed as its configuration says; adds the wall and CPU seconds. */
static int events(fs_wedge_model *w, int count, double *wall, double *cpu, int *done)
{
    bool local = w->cfg.solver.relax == FS_RELAX_LOCAL;
    *done = 0;
    for (int k = 0; k < count && fs_wedge_split_max_ratio(w) > 1.0; k++) {
        double t0 = fs_seconds(), c0 = cpu_seconds();
        int changed = 0;
        int rc = fs_wedge_split_event(w, &changed);
        if (rc < 0)
            return -1;
        if (rc == 1)
            break;
        if (changed && (local ? fs_wedge_relax(w, NULL, 0) : fs_wedge_equilibrium(w, w->time)) < 0)
            return -1;
        *wall += fs_seconds() - t0;
        *cpu += cpu_seconds() - c0;
        *done += changed;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc > 4) {
        usage();
        return 64;
    }
    char *end;
    errno = 0;
    long n = strtol(argv[2], &end, 10);
    long count = argc > 3 ? strtol(argv[3], NULL, 10) : 40;
    if (*end || errno || n < 16 || n > 20000000 || count < 1 || count > 100000) {
        usage();
        return 64;
    }
    fs_log_set_level(FS_LOG_QUIET);
    fs_config cfg = fs_config_default();
    if (fs_preset_load(argv[1], &cfg) < 0 || fs_preset_validate(&cfg, argv[1]) < 0)
        return fail();
    if (cfg.preset.model != FS_MODEL_WEDGE || cfg.fracture.method != FS_FRACTURE_SPLIT) {
        fprintf(stderr, "bench_split: %s is not a wedge preset with fracture.method = split\n", argv[1]);
        return 65;
    }
    cfg.mesh.elements = (int32_t)n;
    fs_domain d = cfg.domain;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = (int32_t)(n / 2); /* a Delaunay mesh has about two triangles per point */
    sp.iterations = cfg.mesh.relax_iterations;
    sp.radius_jitter = cfg.mesh.radius_jitter;
    sp.seed = cfg.preset.seed;
    fs_points pts = {0};
    fs_mesh m_local = {0}, m_global = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0 || fs_delaunay(&d, &pts, &m_local) < 0 ||
        fs_delaunay(&d, &pts, &m_global) < 0)
        return fail();
    fs_points_free(&pts);

    fs_model_setup local = fs_config_model_setup(&cfg), global = local;
    local.solver.relax = FS_RELAX_LOCAL;
    global.solver.relax = FS_RELAX_GLOBAL;
    fs_wedge_model wl, wg;
    if (fs_wedge_init(&wl, &m_local, &local) < 0 || first_fracture(&wl, cfg.time.end, cfg.time.min_step) < 0 ||
        fs_wedge_init(&wg, &m_global, &global) < 0 || fs_wedge_equilibrium(&wg, wl.time) < 0)
        return fail();
    double lw = 0.0, lc = 0.0, gw = 0.0, gc = 0.0;
    int ln = 0, gn = 0;
    if (events(&wl, (int)count, &lw, &lc, &ln) < 0 || events(&wg, (int)count, &gw, &gc, &gn) < 0)
        return fail();
    if (ln == 0 || gn == 0) {
        fprintf(stderr, "bench_split: no fracture event happened\n");
        return 70;
    }
    printf("split %-14s elements %8d  first fracture t = %.4g  events %d/%d  local %8.2f ms (cpu %8.2f ms, %lld "
           "unknowns, %lld fallbacks)  global %8.2f ms (cpu %8.2f ms)  global/local %.1fx wall, %.1fx cpu\n",
           cfg.preset.name, (int)wl.n_elems, wl.time, ln, gn, 1e3 * lw / ln, 1e3 * lc / ln,
           (long long)(wl.counters.local_dofs / (ln ? ln : 1)), (long long)wl.counters.global_fallbacks,
           1e3 * gw / gn, 1e3 * gc / gn, (gw / gn) / (lw / ln), (gc / gn) / (lc / ln));
    fs_wedge_free(&wl);
    fs_wedge_free(&wg);
    fs_mesh_free(&m_local);
    fs_mesh_free(&m_global);
    return 0;
}
