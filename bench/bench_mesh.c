/* Benchmark of sampling, Delaunay meshing and the Voronoi dual: bench_mesh [-j THREADS] N [domain] [uniform]. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/threads.h"
#include "base/vec.h"
#include "geom/delaunay.h"
#include "geom/mesh.h"
#include "geom/sample.h"

/* Target spacing of the points (cm): the domain's area is chosen from it and N. */
#define BENCH_SPACING 0.1

static void usage(void)
{
    fprintf(stderr, "usage: bench_mesh [-j THREADS] N [plane|periodic|cylinder|sphere] [uniform]\n"
                    "  samples N points about %g cm apart by particle repulsion (or uniformly at random with\n"
                    "  'uniform'), triangulates them and builds the Voronoi dual on THREADS threads (default:\n"
                    "  one per processor); prints one line of timings and the mesh's digest\n"
                    "  (fs_mesh_digest), which must not depend on THREADS.\n",
            BENCH_SPACING);
}

/* A domain of the given type whose area holds n points BENCH_SPACING apart (fs_sample_spacing). */
static fs_domain bench_domain(const char *name, int32_t n, bool *ok)
{
    double area = 0.5 * sqrt(3.0) * (double)n * BENCH_SPACING * BENCH_SPACING;
    fs_domain d = fs_domain_default();
    *ok = true;
    if (strcmp(name, "plane") == 0 || strcmp(name, "periodic") == 0) {
        d.width = d.height = sqrt(area);
        d.periodic_x = d.periodic_y = strcmp(name, "periodic") == 0;
    } else if (strcmp(name, "cylinder") == 0) {
        /* unwrapped square: circumference = height */
        d.type = FS_DOMAIN_CYLINDER;
        d.radius = sqrt(area) / (2.0 * FS_PI);
        d.height = sqrt(area);
    } else if (strcmp(name, "sphere") == 0) {
        d.type = FS_DOMAIN_SPHERE;
        d.radius = sqrt(area / (4.0 * FS_PI));
    } else {
        *ok = false;
    }
    fs_domain_normalize(&d);
    return d;
}

/* Uniform random points on the domain (plane/cylinder rectangle, or the sphere). */
static void uniform_points(const fs_domain *d, int32_t n, fs_points *out)
{
    out->n = n;
    out->p = fs_calloc(3 * (size_t)n, sizeof *out->p);
    for (int32_t i = 0; i < n; i++) {
        double u = fs_rand01(1, FS_RNG_TEST, 2 * (uint64_t)i), v = fs_rand01(1, FS_RNG_TEST, 2 * (uint64_t)i + 1);
        double *p = out->p + 3 * (size_t)i;
        if (d->type == FS_DOMAIN_SPHERE) {
            double z = 2.0 * u - 1.0, s = sqrt(1.0 - z * z), phi = 2.0 * FS_PI * v;
            p[0] = d->radius * s * cos(phi);
            p[1] = d->radius * s * sin(phi);
            p[2] = d->radius * z;
        } else {
            p[0] = u * fs_domain_extent_x(d);
            p[1] = v * fs_domain_extent_y(d);
        }
    }
}

int main(int argc, char **argv)
{
    fs_alloc_setup(); /* as the command line tool does */
    char *end;
    if (argc >= 3 && strcmp(argv[1], "-j") == 0) {
        errno = 0;
        long j = strtol(argv[2], &end, 10);
        if (errno || *end || j < 1 || j > FS_THREADS_MAX) {
            usage();
            return FS_ERR_USAGE;
        }
        fs_threads_set((int)j);
        argc -= 2;
        argv += 2;
    }
    if (argc < 2 || argc > 4) {
        usage();
        return FS_ERR_USAGE;
    }
    errno = 0;
    long n = strtol(argv[1], &end, 10);
    if (errno || *end || n < 4 || n > INT32_MAX) {
        usage();
        return FS_ERR_USAGE;
    }
    const char *name = argc >= 3 ? argv[2] : "plane";
    bool uniform = argc >= 4 && strcmp(argv[3], "uniform") == 0;
    if (argc >= 4 && !uniform) {
        usage();
        return FS_ERR_USAGE;
    }
    bool ok;
    fs_domain d = bench_domain(name, (int32_t)n, &ok);
    if (!ok) {
        usage();
        return FS_ERR_USAGE;
    }

    double t0 = fs_seconds();
    fs_points pts = {0, NULL};
    if (uniform) {
        uniform_points(&d, (int32_t)n, &pts);
    } else {
        fs_sample_params sp = fs_sample_params_default();
        sp.count = (int32_t)n;
        if (fs_sample_repulsion(&d, &sp, &pts) != 0) {
            fprintf(stderr, "bench_mesh: %s\n", fs_error_message());
            return fs_error_domain();
        }
    }
    double t1 = fs_seconds();
    fs_mesh m;
    if (fs_delaunay(&d, &pts, &m) != 0) {
        fprintf(stderr, "bench_mesh: %s\n", fs_error_message());
        fs_points_free(&pts);
        return fs_error_domain();
    }
    double t2 = fs_seconds();
    fs_voronoi v;
    if (fs_voronoi_build(&m, &v) != 0) {
        fprintf(stderr, "bench_mesh: %s\n", fs_error_message());
        fs_mesh_free(&m);
        fs_points_free(&pts);
        return fs_error_domain();
    }
    double t3 = fs_seconds();
    printf("%s n=%ld threads=%d %s=%.2fs delaunay=%.2fs voronoi=%.2fs total=%.2fs triangles=%ld boundary_edges=%ld "
           "mesh=%016llx\n",
           name, n, fs_threads(), uniform ? "uniform" : "sample", t1 - t0, t2 - t1, t3 - t2, t3 - t0, (long)m.n_tris,
           (long)fs_mesh_count_boundary_edges(&m), (unsigned long long)fs_mesh_digest(&m));
    fs_voronoi_free(&v);
    fs_mesh_free(&m);
    fs_points_free(&pts);
    return 0;
}
