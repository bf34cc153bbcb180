/* Test helper: whether the cracks in a map rendered into a mesh's own UV layout continue across its UV seams. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "base/error.h"
#include "geom/mesh.h"
#include "geom/uvmesh.h"
#include "image/image.h"

/* A crack pixel: at least half white in the anti-aliased mask; the other side of an edge counts as
 * cracked from a fifth (a thin crack crossing at an angle is anti-aliased differently on each side). */
#define CRACK 0.5f
#define PARTNER 0.2f
/* Samples per pixel of an edge's length on the map. */
#define SAMPLES_PER_PIXEL 1.0
/* How far inside its triangle each side is read (pixels), and how far along the edge a crack on one
 * side may be from one on the other (pixels: the crack crosses the seam at an angle). */
#define INSET 1.5
#define SLACK 3.0

static float mask_at(const float *g, int w, int h, double u, double v)
{
    int x = (int)floor(u * w), y = (int)floor((1.0 - v) * h);
    x = x < 0 ? 0 : (x >= w ? w - 1 : x);
    y = y < 0 ? 0 : (y >= h ? h - 1 : y);
    return g[(size_t)y * w + x];
}

/* The texture point at fraction s along edge e of triangle t, moved inset pixels towards the
 * triangle's third corner. */
static void inside_point(const double *uv, int32_t t, int e, double s, double inset, int w, double out[2])
{
    const double *a = uv + 6 * (size_t)t + 2 * e, *b = uv + 6 * (size_t)t + 2 * ((e + 1) % 3),
                 *c = uv + 6 * (size_t)t + 2 * ((e + 2) % 3);
    double p[2] = {a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])};
    double d[2] = {c[0] - p[0], c[1] - p[1]}, len = hypot(d[0], d[1]);
    double step = inset / w;
    out[0] = p[0] + (len > 0.0 ? d[0] / len * fmin(step, 0.5 * len) : 0.0);
    out[1] = p[1] + (len > 0.0 ? d[1] / len * fmin(step, 0.5 * len) : 0.0);
}

/* Counts the runs of crack along one side of an edge (n samples) and those with crack on the other
 * side within their extent and slack samples either way. */
static void match_runs(const float *side, const float *other, int n, int slack, long *runs, long *matched)
{
    for (int k = 0; k < n;) {
        if (side[k] < CRACK) {
            k++;
            continue;
        }
        int j = k;
        while (j < n && side[j] >= CRACK)
            j++;
        int found = 0;
        for (int q = k - slack; q < j + slack && !found; q++)
            found = q >= 0 && q < n && other[q] >= PARTNER;
        (*runs)++;
        *matched += found;
        k = j;
    }
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: seam_check MESH.obj CRACKMASK.png\n"
                        "prints: SEAM_EDGES SEAM_RUNS SEAM_MATCHED EDGES RUNS MATCHED: along the UV seams, then\n"
                        "along the other interior edges, the runs of crack just inside one side of an edge and\n"
                        "how many of them have crack just inside the other side within a few pixels\n");
        return 2;
    }
    fs_mesh m = {0};
    double *uv = NULL;
    float *g = NULL;
    int w = 0, h = 0;
    if (fs_uvmesh_read(argv[1], &m, &uv) < 0 || fs_image_read_grey(argv[2], &w, &h, &g) < 0) {
        fprintf(stderr, "seam_check: %s\n", fs_error_message());
        return 1;
    }
    long edges[2] = {0, 0}, runs[2] = {0, 0}, matched[2] = {0, 0}; /* [1]: seams */
    for (int32_t t = 0; t < m.n_tris; t++)
        for (int e = 0; e < 3; e++) {
            int32_t o = m.adj[3 * (size_t)t + e];
            if (o < t) /* each interior edge once (and not the boundary) */
                continue;
            int32_t a = m.tri[3 * (size_t)t + e], b = m.tri[3 * (size_t)t + (e + 1) % 3];
            int f = 0; /* the same edge in o runs from b to a */
            while (f < 3 && !(m.tri[3 * (size_t)o + f] == b && m.tri[3 * (size_t)o + (f + 1) % 3] == a))
                f++;
            if (f == 3)
                continue;
            const double *ta = uv + 6 * (size_t)t + 2 * e, *tb = uv + 6 * (size_t)t + 2 * ((e + 1) % 3);
            const double *ob = uv + 6 * (size_t)o + 2 * f, *oa = uv + 6 * (size_t)o + 2 * ((f + 1) % 3);
            double gap = fmax(hypot(ta[0] - oa[0], ta[1] - oa[1]), hypot(tb[0] - ob[0], tb[1] - ob[1]));
            int seam = gap * w >= 1.0; /* else both sides share one texture edge */
            double len_t = hypot((tb[0] - ta[0]) * w, (tb[1] - ta[1]) * h);
            double len_o = hypot((ob[0] - oa[0]) * w, (ob[1] - oa[1]) * h);
            int n = (int)ceil(SAMPLES_PER_PIXEL * fmax(len_t, len_o)) + 1;
            int slack = (int)ceil(SLACK * n / fmax(fmin(len_t, len_o), 1.0));
            /* side t at s runs from a to b; side o at the same point of the edge is at 1 - s along its
             * own edge f (from b to a) */
            float *side = malloc(2 * (size_t)n * sizeof *side);
            for (int k = 0; k < n; k++) {
                double s = (k + 0.5) / n, p[2], q[2];
                inside_point(uv, t, e, s, INSET, w, p);
                inside_point(uv, o, f, 1.0 - s, INSET, w, q);
                side[k] = mask_at(g, w, h, p[0], p[1]);
                side[n + k] = mask_at(g, w, h, q[0], q[1]);
            }
            edges[seam]++;
            match_runs(side, side + n, n, slack, &runs[seam], &matched[seam]);
            match_runs(side + n, side, n, slack, &runs[seam], &matched[seam]);
            free(side);
        }
    printf("%ld %ld %ld %ld %ld %ld\n", edges[1], runs[1], matched[1], edges[0], runs[0], matched[0]);
    free(g);
    free(uv);
    fs_mesh_free(&m);
    return 0;
}
