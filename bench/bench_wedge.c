/* Benchmark of the wedge model's equilibrium: assembly, analysis, factorization, solves (CHOLMOD and CG), factor updates, local versus global relaxation per event; bench_wedge N [plane|periodic|sphere] [thickness]. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/error.h"
#include "base/log.h"
#include "base/vec.h"
#include "geom/delaunay.h"
#include "geom/mesh.h"
#include "geom/sample.h"
#include "model/wedge/internal.h"
#include "sim/settings.h"
#include "solve/cg.h"
#include "solve/sparse.h"

/* Target spacing of the mesh points (cm): the domain's area follows from it and N. */
#define BENCH_SPACING 0.1
/* Element removals timed for the factor updates. */
#define BENCH_REMOVALS 50

/* CPU seconds of the process (all threads): the machine running a benchmark may be shared. */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void usage(void)
{
    fprintf(stderr, "usage: bench_wedge N [plane|periodic|sphere] [thickness]\n"
                    "  builds a wedge layer of about N elements (points %g cm apart, default thickness 0.3 cm)\n"
                    "  under uneven shrinkage and prints one line of timings: assembly, symbolic analysis,\n"
                    "  numeric factorization, one CHOLMOD solve, one CG solve of the same system (tolerance\n"
                    "  1e-8, cold start), the mean factor update and solve after element removals, and the\n"
                    "  mean cost of one event's relaxation after the same removals on two fresh models:\n"
                    "  global (re-factorization of the stale factor, solve, all stresses) and local (thesis\n"
                    "  5.8), in wall and CPU seconds.\n",
            BENCH_SPACING);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 4) {
        usage();
        return 64;
    }
    char *end;
    errno = 0;
    long n = strtol(argv[1], &end, 10);
    if (*end || errno || n < 16 || n > 20000000) {
        usage();
        return 64;
    }
    const char *kind = argc > 2 ? argv[2] : "periodic";
    double thickness = argc > 3 ? strtod(argv[3], NULL) : 0.3;
    fs_config cfg = fs_config_default();
    cfg.preset.model = FS_MODEL_WEDGE;
    cfg.fracture.method = FS_FRACTURE_REMOVE;
    cfg.material.young = 10.0;
    cfg.material.threshold = 100.0;
    cfg.material.thickness = thickness;
    cfg.material.jitter = 0.1;
    cfg.shrink.top.n = cfg.shrink.bottom.n = 2;
    cfg.shrink.top.t[1] = cfg.shrink.bottom.t[1] = 1.0;
    cfg.shrink.top.v[1] = 0.01;
    cfg.shrink.bottom.v[1] = 0.005;
    cfg.solver.relax = FS_RELAX_GLOBAL;
    int32_t points = (int32_t)(n / 2);
    double area = 0.5 * sqrt(3.0) * points * BENCH_SPACING * BENCH_SPACING;
    if (!strcmp(kind, "plane") || !strcmp(kind, "periodic")) {
        cfg.domain.width = cfg.domain.height = sqrt(area);
        cfg.domain.periodic_x = cfg.domain.periodic_y = !strcmp(kind, "periodic");
    } else if (!strcmp(kind, "sphere")) {
        cfg.domain.type = FS_DOMAIN_SPHERE;
        cfg.domain.radius = sqrt(area / (4.0 * FS_PI));
    } else {
        usage();
        return 64;
    }
    fs_domain_normalize(&cfg.domain);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = points;
    sp.iterations = 10;
    fs_points pts = {0};
    fs_mesh m = {0};
    if (fs_sample_repulsion(&cfg.domain, &sp, &pts) < 0 || fs_delaunay(&cfg.domain, &pts, &m) < 0) {
        fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
        return 70;
    }
    fs_points_free(&pts);

    fs_model_setup setup = fs_config_model_setup(&cfg);
    fs_wedge_model w;
    if (fs_wedge_init(&w, &m, &setup) < 0 || fs_wedge_equilibrium(&w, 1.0) < 0) {
        fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
        return 70;
    }
    fs_cholesky_info info = fs_cholesky_get_info(w.chol);
    double assemble = w.counters.assemble_seconds, analyze = w.counters.analyze_seconds;
    double factor = w.counters.factor_seconds, solve = w.counters.solve_seconds, stress = w.counters.stress_seconds;

    /* CG on the same system from a cold start */
    double *x = calloc((size_t)w.n_free + 1, sizeof *x);
    fs_cg_params cp = fs_cg_params_default();
    double t0 = fs_seconds(), residual = 0.0;
    int iterations = fs_cg_solve(&w.k_free, w.rhs, x, cp, &residual);
    double cg = fs_seconds() - t0;
    double diff = 0.0, scale = 0.0;
    for (int32_t i = 0; i < w.n_free; i++) {
        diff = fmax(diff, fabs(x[i] - w.x[i]));
        scale = fmax(scale, fabs(w.x[i]));
    }
    free(x);

    /* factor updates after removals, each followed by a solve */
    fs_wedge_counters before = w.counters;
    int32_t removed = 0;
    for (int32_t e = 0; e < w.n_elems && removed < BENCH_REMOVALS; e += w.n_elems / BENCH_REMOVALS + 1) {
        if (fs_wedge_remove(&w, e) < 0 || fs_wedge_equilibrium(&w, 1.0) < 0) {
            fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
            return 70;
        }
        removed++;
    }
    double update = (w.counters.update_seconds - before.update_seconds) / removed;
    double solve_after = (w.counters.solve_seconds - before.solve_seconds) / removed;
    t0 = fs_seconds();
    if (fs_wedge_refactor(&w) < 0) {
        fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
        return 70;
    }
    double refactor = fs_seconds() - t0;

    /* the same removals relaxed after each event: globally (re-factorization of the stale factor, solve,
     * all stresses) and by local relaxation (thesis §5.8), on two fresh models */
    fs_model_setup local = setup;
    local.solver.relax = FS_RELAX_LOCAL;
    if (getenv("RELAX_TOL"))
        local.solver.relax_tolerance = strtod(getenv("RELAX_TOL"), NULL);
    fs_wedge_model wg, wl;
    if (fs_wedge_init(&wg, &m, &local) < 0 || fs_wedge_equilibrium(&wg, 1.0) < 0 || fs_wedge_init(&wl, &m, &local) < 0 ||
        fs_wedge_equilibrium(&wl, 1.0) < 0) {
        fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
        return 70;
    }
    double global_event = 0.0, local_event = 0.0, global_cpu = 0.0, local_cpu = 0.0, diff_local = 0.0, scale_local = 0.0;
    for (int32_t e = 0, k = 0; e < w.n_elems && k < BENCH_REMOVALS; e += w.n_elems / BENCH_REMOVALS + 1, k++) {
        if (fs_wedge_remove(&wg, e) < 0 || fs_wedge_remove(&wl, e) < 0) {
            fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
            return 70;
        }
        t0 = fs_seconds();
        double c0 = cpu_seconds();
        int rc = fs_wedge_equilibrium(&wg, 1.0);
        double t1 = fs_seconds(), c1 = cpu_seconds();
        rc |= fs_wedge_relax(&wl, NULL, 0);
        double t2 = fs_seconds(), c2 = cpu_seconds();
        global_cpu += c1 - c0;
        local_cpu += c2 - c1;
        if (rc < 0) {
            fprintf(stderr, "bench_wedge: %s\n", fs_error_message());
            return 70;
        }
        global_event += t1 - t0;
        local_event += t2 - t1;
    }
    for (size_t i = 0; i < 6 * (size_t)wl.n_nodes; i++) {
        diff_local = fmax(diff_local, fabs(wl.u[i] - wg.u[i]));
        scale_local = fmax(scale_local, fabs(wg.u[i]));
    }
    int64_t relaxations = wl.counters.local_relaxations + wl.counters.global_fallbacks;

    printf("wedge %-8s elements %8d dofs %8d nnz(K) %9d nnz(L) %10.0f flops %9.3g %s %s  assemble %7.3f s  analyze %7.3f s  "
           "factor %7.3f s  solve %7.4f s  stresses %7.4f s  cg %7.3f s (%d it, diff %.1e)  update %7.4f s  "
           "solve-after %7.4f s  refactor %7.3f s  global-event %7.4f s (cpu %7.4f s)  local-event %7.4f s (cpu %7.4f s; "
           "%.1fx wall, %.1fx cpu, %lld/%lld fallbacks, %.0f unknowns, diff %.1e)\n",
           kind, (int)w.n_elems, (int)w.n_free, fs_sparse_matrix_nnz(&w.k_free), info.factor_nonzeros,
           info.flops, info.ordering, info.supernodal ? "supernodal" : "simplicial", assemble, analyze, factor, solve, stress, cg, iterations,
           scale > 0 ? diff / scale : diff, update, solve_after, refactor, global_event / removed, global_cpu / removed,
           local_event / removed, local_cpu / removed, local_event > 0.0 ? global_event / local_event : 0.0,
           local_cpu > 0.0 ? global_cpu / local_cpu : 0.0, (long long)wl.counters.global_fallbacks,
           (long long)relaxations, relaxations ? (double)wl.counters.local_dofs / (double)relaxations : 0.0,
           scale_local > 0 ? diff_local / scale_local : diff_local);
    fs_wedge_free(&wg);
    fs_wedge_free(&wl);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
    return 0;
}
