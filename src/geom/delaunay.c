/* Delaunay triangulation of a point set on a domain through Qhull (the only file that includes Qhull). */
#include "geom/delaunay.h"

#include <libqhull_r/libqhull_r.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/threads.h"
#include "base/vec.h"

/* Two corners whose sine of angle is below this are treated as collinear (a zero-area triangle). */
#define FLAT_SINE 1e-12
/* Perturbation (in mean spacings) that breaks cocircular ties across seams and block cuts. */
#define TIE_PERTURBATION 1e-6
/* Below this many triangles the canonical sort runs on the calling thread. */
#define CANONICAL_PARALLEL_MIN 100000

/* ---- Qhull ---- */

/* The first line of Qhull's error report, for our message. */
static void qhull_first_line(const char *msg, char *out, size_t size)
{
    out[0] = '\0';
    if (!msg)
        return;
    while (*msg == '\n' || *msg == ' ')
        msg++;
    size_t len = strcspn(msg, "\n");
    if (len >= size)
        len = size - 1;
    memcpy(out, msg, len);
    out[len] = '\0';
}

/* Runs Qhull as qh_new_qhull does, but without its output preparation (qh_prepare_output:
 * triangulating non-simplicial facets and marking the "good" ones, three walks over the whole facet
 * list, about a tenth of the run on a large block). Only for runs without merging, whose facets are
 * all simplicial (run_qhull checks). Qhull's error exit longjmps to the setjmp here, as it would to
 * the one in qh_new_qhull: nothing of ours lives in this frame. Returns Qhull's exit code. */
static int qhull_unmerged(qhT *qh, int dim, int32_t npts, double *coords, char *flags, FILE *err)
{
    int code;
    if (!qh->qhmem.ferr)
        qh_meminit(qh, err);
    else
        qh_memcheck(qh);
    qh_initqhull_start(qh, NULL, NULL, err);
    code = setjmp(qh->errexit);
    if (code == 0) {
        qh->NOerrexit = False;
        qh_initflags(qh, flags);
        qh->PROJECTdelaunay = qh->DELAUNAY;
        qh_init_B(qh, coords, npts, dim, False);
        qh_qhull(qh);
        qh_check_output(qh);
    }
    qh->NOerrexit = True;
    return code;
}

/* design: Qhull reports errors by longjmp to a setjmp inside qh_new_qhull (or qhull_unmerged), so
 * no jump crosses our frames; we only read its facet list after a successful return and then free
 * everything. Its messages go to a memory stream, never to the user's terminal; the first line of an error report
 * becomes our message. Delaunay: "d Qbb Qc Qz Qt" lifts to the paraboloid (last coordinate scaled,
 * a point at infinity against cospherical input, triangulated output) and the lower facets are the
 * triangles. Without `merge`, "Q0" also turns off Qhull's merging of nearly coplanar facets: a third
 * faster on evenly spaced points, which are nearly cocircular everywhere; its facets are simplicial
 * without Qt's pass (qhull_unmerged), and its rare failures (a Qhull precision error, a facet that
 * is not a triangle, or a mesh our checks reject) fall back to the merging run. Sphere: "Qt"
 * convex hull, each triangle turned to agree with Qhull's outward normal. Returns triangles as point
 * indices (Delaunay triangles unoriented); with dim 3 and delaunay, tetrahedra (4 indices each,
 * unoriented). */
static int run_qhull(int dim, int32_t npts, double *coords, bool delaunay, bool merge, int32_t **tri_out,
                     int64_t *ntri_out)
{
    const int nv = delaunay && dim == 3 ? 4 : 3; /* vertices per simplex */
    *tri_out = NULL;
    *ntri_out = 0;
    char *msg = NULL;
    size_t msglen = 0;
    FILE *err = open_memstream(&msg, &msglen);
    if (!err)
        err = fopen("/dev/null", "w");
    if (!err) {
        fs_error(FS_ERR_INTERNAL, "delaunay: cannot open a stream for qhull's messages");
        return -1;
    }
    qhT *qh = fs_calloc(1, sizeof *qh);
    qh_zero(qh, err);
    char flags_fast[] = "qhull d Qbb Qz Qt Q0";
    char flags_delaunay[] = "qhull d Qbb Qc Qz Qt";
    char flags_hull[] = "qhull Qt";
    char *flags = !delaunay ? flags_hull : (merge ? flags_delaunay : flags_fast);
    bool unmerged = delaunay && !merge;
    int code = unmerged ? qhull_unmerged(qh, dim, npts, coords, flags, err)
                        : qh_new_qhull(qh, dim, npts, coords, False, flags, NULL, err);

    int rc = 0;
    int32_t *tri = NULL;
    int64_t nt = 0;
    if (code == 0) {
        facetT *facet;
        vertexT *vertex, **vertexp;
        /* one walk over the facet list (it is scattered in memory): qh->num_facets bounds the count */
        int64_t count = qh->num_facets;
        tri = fs_malloc((size_t)(count ? count : 1) * nv * sizeof *tri);
        FORALLfacets {
            if (delaunay && facet->upperdelaunay)
                continue;
            int ids[4] = {-1, -1, -1, -1}, k = 0;
            bool inside = true;
            FOREACHvertex_(facet->vertices) {
                int id = qh_pointid(qh, vertex->point);
                if (k < nv)
                    ids[k] = id;
                k++;
                if (id < 0 || id >= npts)
                    inside = false;
            }
            if (k != nv) {
                fs_error(FS_ERR_INTERNAL, "delaunay: qhull returned a facet with %d vertices %s", k,
                         unmerged ? "without merging" : "despite option Qt");
                rc = -1;
                break;
            }
            if (!inside)
                continue;
            if (nt == count) {
                fs_error(FS_ERR_INTERNAL, "delaunay: qhull's facet list is longer than its count of %lld",
                         (long long)count);
                rc = -1;
                break;
            }
            if (!delaunay) {
                const double *a = coords + 3 * (size_t)ids[0], *b = coords + 3 * (size_t)ids[1],
                             *c = coords + 3 * (size_t)ids[2];
                double ab[3], ac[3], n[3];
                fs_sub3(ab, b, a);
                fs_sub3(ac, c, a);
                fs_cross3(n, ab, ac);
                if (n[0] * facet->normal[0] + n[1] * facet->normal[1] + n[2] * facet->normal[2] < 0.0) {
                    int s = ids[1];
                    ids[1] = ids[2];
                    ids[2] = s;
                }
            }
            for (int c = 0; c < nv; c++)
                tri[nv * nt + c] = ids[c];
            nt++;
        }
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(qh, &curlong, &totlong);
    free(qh);
    fclose(err);
    if (code != 0) {
        char line[200];
        qhull_first_line(msg, line, sizeof line);
        fs_error(code == qh_ERRsingular ? FS_ERR_DATA : FS_ERR_INTERNAL, "delaunay: qhull: exit code %d: %s", code,
                 line[0] ? line : "(no message)");
        rc = -1;
    }
    free(msg);
    if (rc != 0) {
        free(tri);
        return -1;
    }
    *tri_out = tri;
    *ntri_out = nt;
    return 0;
}

/* ---- input checks ---- */

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

static uint64_t coord_bits(double x)
{
    uint64_t u;
    x += 0.0; /* -0 and +0 are the same point */
    memcpy(&u, &x, sizeof u);
    return u;
}

/* Finds two exactly coincident points (open addressing on the coordinate bits). */
static bool find_duplicate(const double *pos, int32_t n, int32_t *i_out, int32_t *j_out)
{
    size_t size = 16;
    while (size < 2 * (size_t)n)
        size *= 2;
    int32_t *table = fs_malloc(size * sizeof *table);
    for (size_t s = 0; s < size; s++)
        table[s] = -1;
    bool found = false;
    for (int32_t i = 0; i < n && !found; i++) {
        const double *p = pos + 3 * (size_t)i;
        uint64_t h = mix64(coord_bits(p[0]) ^ mix64(coord_bits(p[1]) ^ mix64(coord_bits(p[2]))));
        size_t s = (size_t)h & (size - 1);
        while (table[s] >= 0) {
            const double *q = pos + 3 * (size_t)table[s];
            if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) {
                *i_out = table[s];
                *j_out = i;
                found = true;
                break;
            }
            s = (s + 1) & (size - 1);
        }
        if (!found)
            table[s] = i;
    }
    free(table);
    return found;
}

/* Whether all points lie (nearly) on one line of the plane. */
static bool all_collinear(const double *pos, int32_t n)
{
    const double *p0 = pos;
    int32_t far = 0;
    double best = 0.0;
    for (int32_t i = 1; i < n; i++) {
        double d = hypot(pos[3 * (size_t)i] - p0[0], pos[3 * (size_t)i + 1] - p0[1]);
        if (d > best) {
            best = d;
            far = i;
        }
    }
    if (best == 0.0)
        return true;
    const double *p1 = pos + 3 * (size_t)far;
    for (int32_t i = 0; i < n; i++)
        if (fabs(fs_orient2(p0, p1, pos + 3 * (size_t)i)) > FLAT_SINE * best * best)
            return false;
    return true;
}

/* Whether all points lie (nearly) on one plane (then the hull has no volume). */
static bool all_coplanar(const double *pos, int32_t n, double scale)
{
    const double *p0 = pos, *p1 = NULL, *p2 = NULL;
    double best = 0.0, d[3], e[3], c[3];
    for (int32_t i = 1; i < n; i++) {
        fs_sub3(d, pos + 3 * (size_t)i, p0);
        if (fs_norm3(d) > best) {
            best = fs_norm3(d);
            p1 = pos + 3 * (size_t)i;
        }
    }
    if (!p1)
        return true;
    fs_sub3(d, p1, p0);
    best = 0.0;
    for (int32_t i = 0; i < n; i++) {
        fs_sub3(e, pos + 3 * (size_t)i, p0);
        fs_cross3(c, d, e);
        if (fs_norm3(c) > best) {
            best = fs_norm3(c);
            p2 = pos + 3 * (size_t)i;
        }
    }
    if (!p2 || best <= FLAT_SINE * scale * scale)
        return true;
    fs_sub3(e, p2, p0);
    double nrm[3];
    fs_cross3(nrm, d, e);
    for (int32_t i = 0; i < n; i++) {
        fs_sub3(e, pos + 3 * (size_t)i, p0);
        if (fabs(fs_dot3(nrm, e)) > FLAT_SINE * scale * scale * scale)
            return false;
    }
    return true;
}

/* Whether the triangle with doubled signed area o is too flat to keep. A sine well above the limit
 * (the squares compared with a factor 2 to spare, far beyond rounding) answers without the two
 * hypot calls; near the limit, or for lengths whose squares could underflow or overflow, the test
 * is the exact one. */
static bool is_flat(const double *a, const double *b, const double *c, double o)
{
    double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
    double q = (bx * bx + by * by) * (cx * cx + cy * cy);
    if (q > 1e-200 && q < 1e200 && o * o > 2.0 * FLAT_SINE * FLAT_SINE * q)
        return false;
    double ab = hypot(bx, by), ac = hypot(cx, cy);
    return fabs(o) <= FLAT_SINE * ab * ac;
}

/* ---- mesh checks ---- */

/* First node that is no triangle's corner, or -1. */
static int32_t unused_node(const fs_mesh *m)
{
    uint8_t *used = fs_calloc((size_t)m->n_nodes, 1);
    for (int64_t k = 0; k < 3 * (int64_t)m->n_tris; k++)
        used[m->tri[k]] = 1;
    int32_t v = -1;
    for (int32_t i = 0; i < m->n_nodes && v < 0; i++)
        if (!used[i])
            v = i;
    free(used);
    return v;
}

static int64_t euler_characteristic(const fs_mesh *m)
{
    return (int64_t)m->n_nodes - m->n_edges + m->n_tris;
}

static void drop_mesh_triangles(fs_mesh *m)
{
    free(m->tri);
    free(m->shift);
    free(m->adj);
    free(m->edge);
    free(m->edge_tri);
    free(m->tri_edge);
    m->tri = m->adj = m->edge = m->edge_tri = m->tri_edge = NULL;
    m->shift = NULL;
    m->n_tris = m->n_edges = 0;
}

/* Whether corner a sorts before corner b: by node, then image shift. */
static bool corner_less(int32_t na, const int8_t *sa, int32_t nb, const int8_t *sb)
{
    if (na != nb)
        return na < nb;
    return sa[0] != sb[0] ? sa[0] < sb[0] : sa[1] < sb[1];
}

/* Triangles from one source (a block, or the whole hull), each already starting at its smallest
 * corner with shift (0, 0). */
typedef struct {
    const int32_t *tri;
    const int8_t *shift;
    int64_t n;
} tri_run;

/* The shared state of sort_canonical's parallel passes. */
typedef struct {
    const tri_run *run;
    int32_t n_nodes;
    int64_t *start;       /* n_nodes + 1: triangles counted per first node, then where the next goes */
    int32_t *tri;         /* the output */
    int8_t *shift;
    int parts;            /* node ranges of the last pass */
} canonical_sort;

/* Pass 1 of sort_canonical for one run: its triangles counted by first node. */
static void canonical_count(void *ctx, int32_t r)
{
    canonical_sort *cs = ctx;
    const tri_run *run = &cs->run[r];
    for (int64_t t = 0; t < run->n; t++)
        cs->start[run->tri[3 * t] + 1]++;
}

/* Pass 2 for one run: each of its triangles to the next place of its first node. */
static void canonical_scatter(void *ctx, int32_t r)
{
    canonical_sort *cs = ctx;
    const tri_run *run = &cs->run[r];
    for (int64_t t = 0; t < run->n; t++) {
        int64_t k = cs->start[run->tri[3 * t]]++;
        memcpy(cs->tri + 3 * k, run->tri + 3 * t, 3 * sizeof *cs->tri);
        memcpy(cs->shift + 6 * k, run->shift + 6 * t, 6 * sizeof *cs->shift);
    }
}

/* Pass 3 for one range of first nodes: insertion sort of each node's few triangles by the remaining
 * corners (start[v] now ends node v's triangles). */
static void canonical_within(void *ctx, int32_t part)
{
    canonical_sort *cs = ctx;
    int32_t v0, v1;
    fs_parallel_part(cs->n_nodes, cs->parts, part, &v0, &v1);
    int32_t *tri = cs->tri;
    int8_t *shift = cs->shift;
    int64_t t0 = v0 == 0 ? 0 : cs->start[v0 - 1], t1 = v1 == 0 ? 0 : cs->start[v1 - 1];
    for (int64_t t = t0 + 1; t < t1; t++) {
        for (int64_t k = t; k > t0 && tri[3 * k] == tri[3 * (k - 1)]; k--) {
            const int32_t *a = tri + 3 * (k - 1), *b = tri + 3 * k;
            const int8_t *sa = shift + 6 * (k - 1), *sb = shift + 6 * k;
            bool swap = corner_less(b[1], sb + 2, a[1], sa + 2) ||
                        (b[1] == a[1] && sb[2] == sa[2] && sb[3] == sa[3] && corner_less(b[2], sb + 4, a[2], sa + 4));
            if (!swap)
                break;
            int32_t tv[3];
            int8_t ts[6];
            memcpy(tv, a, sizeof tv);
            memcpy(ts, sa, sizeof ts);
            memcpy(tri + 3 * (k - 1), b, sizeof tv);
            memcpy(shift + 6 * (k - 1), sb, sizeof ts);
            memcpy(tri + 3 * k, tv, sizeof tv);
            memcpy(shift + 6 * k, ts, sizeof ts);
        }
    }
}

/* design: triangles are stored in a canonical order that depends only on the mesh, not on Qhull's
 * facet order nor on the blocks (below): each starts at its smallest corner (node, then shift; the
 * triangle is shifted so that corner has shift (0, 0)), and triangles are sorted by their corners:
 * a stable counting sort on the first node over the runs in order, then an insertion sort within
 * a node's few triangles. The runs are counted and scattered in parallel, which needs every node's
 * triangles to come from one run (a block keeps exactly the triangles whose first node it owns):
 * then no two runs touch one node's counter, and each node's triangles keep their order in their
 * run, as in one pass over the runs. The node ranges of the insertion sort are independent. The
 * result does not depend on the thread count. Writes the n_tris triangles to tri and shift. */
static void sort_canonical(const tri_run *run, int nruns, int32_t n_nodes, int32_t *tri, int8_t *shift)
{
    canonical_sort cs = {run, n_nodes, fs_calloc((size_t)n_nodes + 1, sizeof *cs.start), tri, shift, 1};
    int64_t total = 0;
    for (int r = 0; r < nruns; r++)
        total += run[r].n;
    int threads = total >= CANONICAL_PARALLEL_MIN ? fs_threads() : 1;
    fs_parallel_for(nruns, threads, canonical_count, &cs);
    for (int32_t v = 0; v < n_nodes; v++)
        cs.start[v + 1] += cs.start[v];
    fs_parallel_for(nruns, threads, canonical_scatter, &cs);
    cs.parts = threads < n_nodes ? threads : 1;
    fs_parallel_for(cs.parts, threads, canonical_within, &cs);
    free(cs.start);
}

/* Rotates each triangle to start at its smallest corner (node, then shift), shifted so that corner
 * has shift (0, 0). */
static void rotate_canonical(int32_t *tri, int8_t *shift, int64_t nt)
{
    for (int64_t t = 0; t < nt; t++) {
        int32_t *v = tri + 3 * t;
        int8_t *s = shift + 6 * t;
        int first = 0;
        for (int c = 1; c < 3; c++)
            if (corner_less(v[c], s + 2 * c, v[first], s + 2 * first))
                first = c;
        int32_t nv[3];
        int8_t ns[6];
        for (int c = 0; c < 3; c++) {
            int k = (first + c) % 3;
            nv[c] = v[k];
            ns[2 * c] = (int8_t)(s[2 * k] - s[2 * first]);
            ns[2 * c + 1] = (int8_t)(s[2 * k + 1] - s[2 * first + 1]);
        }
        memcpy(v, nv, sizeof nv);
        memcpy(s, ns, sizeof ns);
    }
}

/* Puts the triangles of one set in canonical order (see sort_canonical), in place. */
static void canonical_order(int32_t *tri, int8_t *shift, int64_t nt, int32_t n_nodes)
{
    rotate_canonical(tri, shift, nt);
    int32_t *tri2 = fs_malloc((size_t)(nt ? nt : 1) * 3 * sizeof *tri2);
    int8_t *shift2 = fs_malloc((size_t)(nt ? nt : 1) * 6 * sizeof *shift2);
    tri_run run = {tri, shift, nt};
    sort_canonical(&run, 1, n_nodes, tri2, shift2);
    memcpy(tri, tri2, (size_t)nt * 3 * sizeof *tri);
    memcpy(shift, shift2, (size_t)nt * 6 * sizeof *shift);
    free(tri2);
    free(shift2);
}

/* ---- sphere ---- */

static int triangulate_sphere(fs_mesh *m)
{
    int32_t n = m->n_nodes;
    double r = m->domain.radius;
    if (!(r > 0.0) || !isfinite(r)) {
        fs_error(FS_ERR_DATA, "delaunay: sphere radius %g: expected a positive number", r);
        return -1;
    }
    for (int32_t i = 0; i < n; i++) {
        double d = fs_norm3(m->pos + 3 * (size_t)i);
        if (fabs(d - r) > 1e-6 * r) {
            fs_error(FS_ERR_DATA, "delaunay: point %d is at distance %g from the centre, not on the sphere of radius %g",
                     (int)i, d, r);
            return -1;
        }
    }
    if (all_coplanar(m->pos, n, r)) {
        fs_error(FS_ERR_DATA, "delaunay: all %d points lie on one circle of the sphere", (int)n);
        return -1;
    }
    double *xyz = fs_malloc(3 * (size_t)n * sizeof *xyz);
    memcpy(xyz, m->pos, 3 * (size_t)n * sizeof *xyz);
    int32_t *tri;
    int64_t nt;
    int rc = run_qhull(3, n, xyz, false, true, &tri, &nt);
    free(xyz);
    if (rc != 0)
        return -1;
    /* every hull facet must face away from the centre: otherwise the points leave a hole larger than
     * a hemisphere and the hull cuts through the ball */
    for (int64_t t = 0; t < nt; t++) {
        const double *a = m->pos + 3 * (size_t)tri[3 * t], *b = m->pos + 3 * (size_t)tri[3 * t + 1],
                     *c = m->pos + 3 * (size_t)tri[3 * t + 2];
        double ab[3], ac[3], nrm[3];
        fs_sub3(ab, b, a);
        fs_sub3(ac, c, a);
        fs_cross3(nrm, ab, ac);
        if (fs_dot3(nrm, a) <= 1e-9 * fs_norm3(nrm) * r) {
            free(tri);
            fs_error(FS_ERR_DATA, "delaunay: the points do not surround the centre of the sphere (a cap is empty)");
            return -1;
        }
    }
    int8_t *shift = fs_calloc((size_t)(nt ? nt : 1) * 6, sizeof *shift);
    canonical_order(tri, shift, nt, n);
    m->n_tris = (int32_t)nt;
    m->tri = tri;
    m->shift = shift;
    int32_t v = unused_node(m);
    if (v >= 0) {
        fs_error(FS_ERR_DATA, "delaunay: point %d is not a vertex of the hull: it (nearly) coincides with another point",
                 (int)v);
        return -1;
    }
    if (fs_mesh_build_adjacency(m) != 0) {
        char why[512];
        snprintf(why, sizeof why, "%s", fs_error_message());
        fs_error(FS_ERR_INTERNAL, "delaunay: qhull's hull is not a manifold (%s)", why);
        return -1;
    }
    fs_mesh_build_edges(m);
    if (euler_characteristic(m) != 2) {
        fs_error(FS_ERR_INTERNAL, "delaunay: the sphere mesh has Euler characteristic %lld, expected 2",
                 (long long)euler_characteristic(m));
        return -1;
    }
    fs_mesh_build_rings(m);
    return 0;
}

/* ---- plane, periodic plane and cylinder ---- */

/* Points per block; a large set is cut into blocks triangulated in parallel, at most MAX_BLOCKS
 * strips. Smaller Qhull runs are faster per point: a million evenly spaced points triangulate about
 * a tenth faster in 16 strips than in 8, while 31 or 62 strips of 32768 or 16384 points gain nothing
 * more (the margins copied beyond each strip grow relative to it). */
#define BLOCK_POINTS 65536
#define MAX_BLOCKS 16

typedef struct {
    int32_t n;
    double *base;         /* 2 n coordinates fed to Qhull (positions, perturbed when breaking ties) */
    uint8_t *owner;       /* block of each node */
    double period[2];     /* extent of a wrapping direction, 0 for one that does not wrap */
    double lo[2], hi[2];  /* range of the base coordinates per direction */
    int axis;             /* direction cut into blocks */
    int nblocks;
    double cut0, cut_width; /* block b covers [cut0 + b w, cut0 + (b + 1) w) along axis */
    double max_margin;    /* beyond this the input is taken as degenerate */
    double slack;         /* added to circumcircles against rounding (a billionth of the spacing) */
    bool merge;           /* run Qhull with facet merging (see run_qhull) */
} plane_setup;

typedef struct {
    const plane_setup *s;
    int b;
    double margin;        /* copies are made of points within this distance beyond the block */
    int status;           /* 0 done, -1 error (err_*), 1 the margin would exceed its limit */
    int32_t *tri;         /* 3 per owned triangle */
    int8_t *shift;        /* 6 per owned triangle */
    int64_t n_tris;
    fs_errdomain err_domain;
    char err[1024];
} block_job;

/* Half of the extent along direction d of the circumcircle (centre c, through corner a) restricted
 * to the band the points occupy in the other direction (the whole disc when that direction wraps).
 * The chord where the circle crosses the band's edge e is computed from the corner,
 * (a_d - c_d)^2 + (a_o - e)(a_o + e - 2 c_o), which stays accurate for the huge circles of the
 * slivers along a band's edge. */
static double disc_half_extent(const plane_setup *s, int d, const double *c, const double *a, double r)
{
    int o = 1 - d;
    if (s->period[o] > 0.0 || (c[o] >= s->lo[o] && c[o] <= s->hi[o]))
        return r;
    double e = c[o] < s->lo[o] ? s->lo[o] : s->hi[o];
    double half2 = (a[d] - c[d]) * (a[d] - c[d]) + (a[o] - e) * (a[o] + e - 2.0 * c[o]);
    return half2 > 0.0 ? sqrt(half2) : 0.0;
}

/* Whether the circle with centre c and squared radius r2 lies inside the region [lo, hi) as
 * run_block's test measures it, decided without its hypot: the bound sqrt(r2) (1 + 1e-9) is at
 * least hypot's radius whenever r2 is a normal number, rounding is monotonic, and the whole disc
 * is what disc_half_extent measures when the centre lies in the band. Otherwise (false) the exact
 * test decides. */
static bool circle_surely_inside(const plane_setup *s, const double *c, double r2, const double *lo, const double *hi)
{
    if (!(r2 > 1e-290 && r2 < 1e290))
        return false;
    double half = sqrt(r2) * (1.0 + 1e-9) + s->slack;
    for (int d = 0; d < 2; d++) {
        int o = 1 - d;
        if (!(s->period[o] > 0.0 || (c[o] >= s->lo[o] && c[o] <= s->hi[o])))
            return false;
        if (!(c[d] - half >= lo[d] && c[d] + half <= hi[d]))
            return false;
    }
    return true;
}

/* The region whose points (and images) block b copies: the block widened by the margin, the whole
 * period plus the margin across a wrapping direction, unbounded at the outer ends of a direction
 * that does not wrap. */
static void block_region(const plane_setup *s, int b, double margin, double *lo, double *hi)
{
    for (int d = 0; d < 2; d++) {
        lo[d] = s->period[d] > 0.0 ? -margin : -INFINITY;
        hi[d] = s->period[d] > 0.0 ? s->period[d] + margin : INFINITY;
    }
    int a = s->axis;
    bool wraps = s->period[a] > 0.0;
    lo[a] = (b == 0 && !wraps) ? -INFINITY : s->cut0 + b * s->cut_width - margin;
    hi[a] = (b == s->nblocks - 1 && !wraps) ? INFINITY : s->cut0 + (b + 1) * s->cut_width + margin;
}

/* Most periodic copies of one point per direction that a block makes. */
#define MAX_IMAGES 100

/* Range [k0, k1] of image shifts k with lo <= x + k period < hi (k = 0 only, if it fits, for a
 * direction that does not wrap). Returns 0 when empty, 1 when not, and -1 when the range holds more
 * than MAX_IMAGES shifts (a period tiny beside the margin: the shifts are counted in double
 * precision, so no count overflows an int). */
static int image_range(double x, double period, double lo, double hi, int *k0, int *k1)
{
    if (period == 0.0) {
        *k0 = *k1 = 0;
        return x >= lo && x < hi;
    }
    double a = ceil((lo - x) / period), b = ceil((hi - x) / period) - 1.0;
    if (!(b - a <= MAX_IMAGES))
        return -1;
    *k0 = (int)a;
    *k1 = (int)b;
    return *k0 <= *k1;
}

static void block_fail(block_job *job)
{
    job->status = -1;
    job->err_domain = fs_error_domain();
    snprintf(job->err, sizeof job->err, "%s", fs_error_message());
}

/* design: one block of the 2-D triangulation (see triangulate_2d). The nodes the block owns and
 * every image of every node within the block's region are triangulated together; a triangle's
 * corners are (node, image shift). Its copies differ by a common shift, and exactly one copy has its
 * smallest corner at shift (0, 0); that copy is kept by the block owning that node. The copy set is
 * good enough when every triangle touching an owned shift-(0, 0) node has its circumcircle, as far as
 * it meets the band the points occupy, inside the region: then its emptiness holds for the whole
 * (periodic) point set and the fans of the owned nodes are their true Delaunay fans. Otherwise the
 * margin grows to what the failing circles need, at least doubling (points that do not lie exactly
 * on the edges of a band periodic in one direction make hull edges as long as the period). */
static void run_block(block_job *job)
{
    const plane_setup *s = job->s;
    int32_t n = s->n;
    bool merge = s->merge;
    for (;;) {
        double lo[2], hi[2];
        block_region(s, job->b, job->margin, lo, hi);
        double *xy = NULL;
        int32_t *node = NULL;
        int8_t *shift = NULL;
        int64_t count = 0;
        for (int pass = 0; pass < 2; pass++) {
            count = 0;
            for (int32_t i = 0; i < n; i++) {
                int k0[2], k1[2];
                int in_x = image_range(s->base[2 * i], s->period[0], lo[0], hi[0], &k0[0], &k1[0]);
                int in_y = image_range(s->base[2 * i + 1], s->period[1], lo[1], hi[1], &k0[1], &k1[1]);
                if ((in_x == 0 && in_y >= 0) || (in_y == 0 && in_x >= 0))
                    continue;
                if (in_x < 0 || in_y < 0) {
                    free(xy);
                    free(node);
                    free(shift);
                    fs_error(FS_ERR_DATA,
                             "delaunay: %d points are too few for a periodic domain this elongated: the "
                             "triangulation would need more than %d periodic copies",
                             (int)n, MAX_IMAGES);
                    block_fail(job);
                    return;
                }
                for (int kx = k0[0]; kx <= k1[0]; kx++)
                    for (int ky = k0[1]; ky <= k1[1]; ky++) {
                        if (pass == 1) {
                            xy[2 * count] = s->base[2 * i] + kx * s->period[0];
                            xy[2 * count + 1] = s->base[2 * i + 1] + ky * s->period[1];
                            node[count] = i;
                            shift[2 * count] = (int8_t)kx;
                            shift[2 * count + 1] = (int8_t)ky;
                        }
                        count++;
                    }
            }
            if (pass == 0 && count > INT32_MAX) {
                fs_error(FS_ERR_DATA, "delaunay: too many points with their periodic copies (%lld)", (long long)count);
                block_fail(job);
                return;
            }
            if (pass == 0) {
                xy = fs_malloc(2 * (size_t)(count ? count : 1) * sizeof *xy);
                node = fs_malloc((size_t)(count ? count : 1) * sizeof *node);
                shift = fs_malloc(2 * (size_t)(count ? count : 1) * sizeof *shift);
            }
        }

        int32_t *tri = NULL;
        int64_t nt = 0;
        int qrc = count < 3 ? -1 : run_qhull(2, (int32_t)count, xy, true, merge, &tri, &nt);
        if (qrc != 0 && count >= 3 && !merge) {
            free(xy);
            free(node);
            free(shift);
            merge = true;
            continue;
        }
        if (qrc != 0) {
            if (count < 3)
                fs_error(FS_ERR_INTERNAL, "delaunay: block %d has only %lld points", job->b, (long long)count);
            free(xy);
            free(node);
            free(shift);
            block_fail(job);
            return;
        }

        int32_t *keep_tri = fs_malloc((size_t)(nt ? nt : 1) * 3 * sizeof *keep_tri);
        int8_t *keep_shift = fs_malloc((size_t)(nt ? nt : 1) * 6 * sizeof *keep_shift);
        int64_t kept = 0;
        double needed = 0.0;
        for (int64_t t = 0; t < nt; t++) {
            int32_t e[3] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
            const double *pa = xy + 2 * (size_t)e[0], *pb = xy + 2 * (size_t)e[1], *pc = xy + 2 * (size_t)e[2];
            double o = fs_orient2(pa, pb, pc);
            if (is_flat(pa, pb, pc, o))
                continue;
            if (o < 0.0) {
                int32_t sw = e[1];
                e[1] = e[2];
                e[2] = sw;
            }
            bool touches = false;
            int first = 0;
            for (int c = 0; c < 3; c++) {
                const int8_t *sc = shift + 2 * (size_t)e[c];
                touches |= sc[0] == 0 && sc[1] == 0 && s->owner[node[e[c]]] == job->b;
                if (c > 0 && corner_less(node[e[c]], sc, node[e[first]], shift + 2 * (size_t)e[first]))
                    first = c;
            }
            if (touches) {
                double bx = pb[0] - pa[0], by = pb[1] - pa[1], cx = pc[0] - pa[0], cy = pc[1] - pa[1];
                double dd = 2.0 * (bx * cy - by * cx);
                double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
                double ux = (cy * b2 - by * c2) / dd, uy = (bx * c2 - cx * b2) / dd;
                double cc[2] = {pa[0] + ux, pa[1] + uy};
                if (!circle_surely_inside(s, cc, ux * ux + uy * uy, lo, hi)) {
                    double r = hypot(ux, uy);
                    for (int d = 0; d < 2; d++) {
                        double half = disc_half_extent(s, d, cc, pa, r) + s->slack;
                        if (cc[d] - half < lo[d])
                            needed = fmax(needed, job->margin + (lo[d] - (cc[d] - half)));
                        if (cc[d] + half > hi[d])
                            needed = fmax(needed, job->margin + (cc[d] + half - hi[d]));
                    }
                }
            }
            const int8_t *sf = shift + 2 * (size_t)e[first];
            if (sf[0] != 0 || sf[1] != 0 || s->owner[node[e[first]]] != job->b)
                continue;
            for (int c = 0; c < 3; c++) {
                int32_t x = e[(first + c) % 3];
                keep_tri[3 * kept + c] = node[x];
                keep_shift[6 * kept + 2 * c] = shift[2 * (size_t)x];
                keep_shift[6 * kept + 2 * c + 1] = shift[2 * (size_t)x + 1];
            }
            kept++;
        }
        free(tri);
        free(xy);
        free(node);
        free(shift);
        if (needed == 0.0) {
            job->tri = keep_tri;
            job->shift = keep_shift;
            job->n_tris = kept;
            job->status = 0;
            return;
        }
        free(keep_tri);
        free(keep_shift);
        /* blocks only pay off while their margins stay narrower than the blocks (and a circle wider
         * than a block, even if it goes away with more points, says the points are not even) */
        double limit = s->nblocks > 1 ? 0.25 * s->cut_width : s->max_margin;
        if (job->margin >= limit || (s->nblocks > 1 && needed > limit)) {
            job->status = 1;
            return;
        }
        job->margin = fmin(fmax(2.0 * job->margin, 1.25 * needed), limit);
    }
}

/* Block j of the jobs ctx, one item of the parallel loop of the blocks. */
static void block_item(void *ctx, int32_t j) { run_block((block_job *)ctx + j); }

typedef enum {
    MESH_OK,
    MESH_ERROR,       /* reported with fs_error */
    MESH_BLOCK_LIMIT, /* a block needed a wider margin than allowed */
    MESH_BOUNDARY,    /* the merged boundary is not the true one: margins too narrow */
    MESH_DEGENERATE   /* not a valid mesh: ties split inconsistently, or a point is no vertex */
} mesh_check;

/* Checks the merged mesh: every node used, a manifold, a boundary that is the true one (none on a
 * torus; along the lowest and highest rows across a band periodic in one direction; a convex loop
 * on the plane), the area of the periodic cell covered once, and the Euler characteristic (0 for
 * a torus or annulus, 1 for a disc). */
static mesh_check check_2d(fs_mesh *m, const plane_setup *s, int32_t *unused)
{
    *unused = unused_node(m);
    if (*unused >= 0 || fs_mesh_build_adjacency(m) != 0)
        return MESH_DEGENERATE;
    int wrapping = (s->period[0] > 0.0) + (s->period[1] > 0.0);
    int32_t nh = 3 * m->n_tris;
    int32_t *out = NULL;
    if (wrapping == 0) {
        out = fs_malloc((size_t)m->n_nodes * sizeof *out);
        for (int32_t v = 0; v < m->n_nodes; v++)
            out[v] = -1;
        for (int32_t h = 0; h < nh; h++) {
            if (m->adj[h] >= 0)
                continue;
            if (out[m->tri[h]] >= 0) {
                free(out);
                return MESH_BOUNDARY;
            }
            out[m->tri[h]] = h;
        }
    }
    mesh_check result = MESH_OK;
    for (int32_t h = 0; h < nh && result == MESH_OK; h++) {
        if (m->adj[h] >= 0)
            continue;
        int32_t a = m->tri[h], b = m->tri[3 * (h / 3) + (h % 3 + 1) % 3];
        const double *pa = m->pos + 3 * (size_t)a, *pb = m->pos + 3 * (size_t)b;
        if (wrapping == 2) {
            result = MESH_DEGENERATE;
        } else if (wrapping == 1) {
            int o = s->period[0] > 0.0 ? 1 : 0;
            if (!((pa[o] == s->lo[o] && pb[o] == s->lo[o]) || (pa[o] == s->hi[o] && pb[o] == s->hi[o])))
                result = MESH_BOUNDARY;
        } else {
            int32_t g = out[b];
            const double *pc = m->pos + 3 * (size_t)m->tri[3 * (g / 3) + (g % 3 + 1) % 3];
            double turn = fs_orient2(pa, pb, pc);
            double lab = hypot(pb[0] - pa[0], pb[1] - pa[1]), lbc = hypot(pc[0] - pb[0], pc[1] - pb[1]);
            if (turn < -FLAT_SINE * lab * lbc)
                result = MESH_BOUNDARY;
        }
    }
    free(out);
    if (result != MESH_OK)
        return result;
    if (wrapping) {
        /* signed areas sum to the cell's area only when the triangles cover it exactly once */
        double area = 0.0, want = 1.0;
        for (int32_t t = 0; t < m->n_tris; t++)
            area += fs_mesh_tri_area(m, t);
        for (int d = 0; d < 2; d++)
            want *= s->period[d] > 0.0 ? s->period[d] : s->hi[d] - s->lo[d];
        if (fabs(area - want) > 1e-9 * want)
            return MESH_DEGENERATE;
    }
    fs_mesh_build_edges(m);
    return euler_characteristic(m) == (wrapping ? 0 : 1) ? MESH_OK : MESH_DEGENERATE;
}

/* One pass over all blocks with the given margin; merges their triangles into m and checks. */
static mesh_check triangulate_blocks(fs_mesh *m, plane_setup *s, double margin, int32_t *unused)
{
    *unused = -1;
    int nb = s->nblocks;
    block_job jobs[MAX_BLOCKS];
    for (int b = 0; b < nb; b++) {
        memset(&jobs[b], 0, sizeof jobs[b]);
        jobs[b].s = s;
        jobs[b].b = b;
        jobs[b].margin = margin;
    }
    /* on up to fs_threads() threads (base/threads.h): the result does not depend on the thread count
     * nor on which thread runs which block (each block's output depends only on the input) */
    fs_parallel_for(nb, 0, block_item, jobs);
    int64_t total = 0;
    int status = 0;
    for (int b = 0; b < nb; b++) {
        if (jobs[b].status == -1 && status != -1) {
            fs_error(jobs[b].err_domain, "%s", jobs[b].err);
            status = -1;
        } else if (jobs[b].status == 1 && status == 0) {
            status = 1;
        }
        total += jobs[b].n_tris;
    }
    if (status == 0 && total > INT32_MAX / 3) {
        fs_error(FS_ERR_DATA, "delaunay: %lld triangles are too many", (long long)total);
        status = -1;
    }
    drop_mesh_triangles(m);
    if (status != 0) {
        for (int b = 0; b < nb; b++) {
            free(jobs[b].tri);
            free(jobs[b].shift);
        }
        return status == -1 ? MESH_ERROR : MESH_BLOCK_LIMIT;
    }
    /* each block's triangles start at their smallest corner, with shift (0, 0), owned by the block */
    m->tri = fs_malloc((size_t)(total ? total : 1) * 3 * sizeof *m->tri);
    m->shift = fs_malloc((size_t)(total ? total : 1) * 6 * sizeof *m->shift);
    tri_run run[MAX_BLOCKS];
    for (int b = 0; b < nb; b++)
        run[b] = (tri_run){jobs[b].tri, jobs[b].shift, jobs[b].n_tris};
    sort_canonical(run, nb, m->n_nodes, m->tri, m->shift);
    for (int b = 0; b < nb; b++) {
        free(jobs[b].tri);
        free(jobs[b].shift);
    }
    m->n_tris = (int32_t)total;
    return check_2d(m, s, unused);
}

/* Whether the points lie on the edges of the band in every direction that does not wrap (at least
 * a quarter of a row each), as the sampler leaves them. Otherwise hull edges may span whole blocks,
 * and one block does better. */
static bool edges_populated(const fs_mesh *m, const plane_setup *s, const double *span, double spacing)
{
    for (int d = 0; d < 2; d++) {
        if (s->period[d] > 0.0)
            continue;
        int32_t at_lo = 0, at_hi = 0;
        for (int32_t i = 0; i < s->n; i++) {
            at_lo += m->pos[3 * (size_t)i + d] == s->lo[d];
            at_hi += m->pos[3 * (size_t)i + d] == s->hi[d];
        }
        double row = 0.25 * span[1 - d] / spacing;
        if (at_lo < row || at_hi < row)
            return false;
    }
    return true;
}

/* Fills base (perturbed in the wrapping directions when asked) and owner. */
static void setup_coordinates(const fs_mesh *m, plane_setup *s, bool perturb, double spacing)
{
    for (int32_t i = 0; i < s->n; i++) {
        for (int d = 0; d < 2; d++) {
            double p = m->pos[3 * (size_t)i + d];
            if (perturb && s->period[d] > 0.0) {
                double w = d == 0 ? 0.6180339887498949 : 0.4142135623730951;
                double frac = fmod((double)(i + 1) * w, 1.0);
                p += TIE_PERTURBATION * spacing * (2.0 * frac - 1.0);
            }
            s->base[2 * i + d] = p;
        }
        double f = floor((s->base[2 * i + s->axis] - s->cut0) / s->cut_width);
        int b = f < 0.0 ? 0 : (f >= s->nblocks ? s->nblocks - 1 : (int)f);
        s->owner[i] = (uint8_t)b;
    }
}

/* design: the plane is the Delaunay triangulation by the paraboloid lift (thesis §5.2.2); a
 * periodic plane or cylinder (the thesis triangulates the unwrapped cylinder; we make it seamless)
 * triangulates the points with their images across the seams and keeps one copy of each triangle
 * (run_block). A large set is cut into blocks along its longer side, run in parallel: a block is
 * the same problem with the other blocks' points in the role of images. The block count depends
 * only on the input, and the triangles are put in canonical order, so the mesh does not depend on
 * the machine or its thread count. Blocks need the points on the edges that do not wrap (the
 * sampler snaps them there): otherwise a hull edge may span blocks, and one block is used. The
 * merged mesh is checked (check_2d); any failure first reruns Qhull with facet merging, then a
 * wrong boundary sends us to one block and grows the margin. Cocircular points on a seam or a
 * block cut may be split differently on the two sides: then we retry with every node moved by a
 * fixed pseudo-random offset of TIE_PERTURBATION spacings in the wrapping directions (the same for
 * all its images, fed only to Qhull), then as one block. */
static int triangulate_2d(fs_mesh *m)
{
    int32_t n = m->n_nodes;
    bool wraps[2] = {m->domain.type == FS_DOMAIN_CYLINDER || m->domain.periodic_x, m->domain.periodic_y};
    double extent[2] = {fs_domain_extent_x(&m->domain), fs_domain_extent_y(&m->domain)};
    plane_setup s;
    memset(&s, 0, sizeof s);
    s.n = n;
    for (int d = 0; d < 2; d++) {
        if (wraps[d] && !(extent[d] > 0.0 && isfinite(extent[d]))) {
            fs_error(FS_ERR_DATA, "delaunay: the domain's period in %c is %g: expected a positive number", "xy"[d],
                     extent[d]);
            return -1;
        }
        s.period[d] = wraps[d] ? extent[d] : 0.0;
        s.lo[d] = s.hi[d] = m->pos[d];
        for (int32_t i = 0; i < n; i++) {
            double p = m->pos[3 * (size_t)i + d];
            s.lo[d] = p < s.lo[d] ? p : s.lo[d];
            s.hi[d] = p > s.hi[d] ? p : s.hi[d];
        }
    }
    if (!wraps[0] && !wraps[1] && all_collinear(m->pos, n)) {
        fs_error(FS_ERR_DATA, "delaunay: all %d points lie on one line", (int)n);
        return -1;
    }
    for (int d = 0; d < 2; d++) {
        if (wraps[d] && !wraps[1 - d] && s.hi[1 - d] - s.lo[1 - d] <= FLAT_SINE * extent[d]) {
            fs_error(FS_ERR_DATA, "delaunay: all %d points lie on one line along the periodic direction", (int)n);
            return -1;
        }
    }
    double span[2], area = 1.0;
    for (int d = 0; d < 2; d++) {
        span[d] = wraps[d] ? s.period[d] : s.hi[d] - s.lo[d];
        area *= span[d] > 0.0 ? span[d] : 1.0;
    }
    double spacing = sqrt(area / n);
    s.axis = span[0] >= span[1] ? 0 : 1;
    s.nblocks = (int)((n + BLOCK_POINTS - 1) / BLOCK_POINTS);
    if (s.nblocks > MAX_BLOCKS)
        s.nblocks = MAX_BLOCKS;
    if (s.nblocks > 1 && !edges_populated(m, &s, span, spacing))
        s.nblocks = 1;
    s.max_margin = 4.0 * fmax(span[0], span[1]);
    s.slack = 1e-9 * spacing;
    s.base = fs_malloc(2 * (size_t)n * sizeof *s.base);
    s.owner = fs_malloc((size_t)n);

    bool perturb = false;
    double margin = 4.0 * spacing;
    int rc = -1;
    for (;;) {
        s.cut0 = wraps[s.axis] ? 0.0 : s.lo[s.axis];
        s.cut_width = span[s.axis] / s.nblocks;
        if (!(s.cut_width > 0.0))
            s.cut_width = 1.0;
        setup_coordinates(m, &s, perturb, spacing);
        int32_t unused;
        mesh_check st = triangulate_blocks(m, &s, margin, &unused);
        if (st == MESH_ERROR)
            break;
        if (st == MESH_OK) {
            fs_mesh_build_rings(m);
            rc = 0;
            break;
        }
        if (st == MESH_BLOCK_LIMIT && s.nblocks > 1) {
            s.nblocks = 1;
            continue;
        }
        if (!s.merge) {
            s.merge = true;
            continue;
        }
        if (st == MESH_BOUNDARY && s.nblocks > 1) {
            s.nblocks = 1;
            continue;
        }
        if (st == MESH_BOUNDARY && margin < s.max_margin && (wraps[0] || wraps[1])) {
            margin = fmin(2.0 * margin, s.max_margin);
            continue;
        }
        if ((wraps[0] || wraps[1]) && !perturb) {
            perturb = true;
            continue;
        }
        if (s.nblocks > 1) {
            s.nblocks = 1;
            continue;
        }
        if (unused >= 0)
            fs_error(FS_ERR_DATA,
                     "delaunay: point %d is not a vertex of the triangulation: it (nearly) coincides with another "
                     "point%s",
                     (int)unused, wraps[0] || wraps[1] ? " or its periodic image" : "");
        else
            fs_error(FS_ERR_INTERNAL, "delaunay: no consistent triangulation of %d points (degenerate input?)",
                     (int)n);
        break;
    }
    free(s.base);
    free(s.owner);
    return rc;
}

int fs_delaunay(const fs_domain *d, const fs_points *pts, fs_mesh *out)
{
    memset(out, 0, sizeof *out);
    fs_domain dom = *d;
    fs_domain_normalize(&dom);
    int32_t n = pts ? pts->n : 0;
    int32_t need = dom.type == FS_DOMAIN_SPHERE ? 4 : 3;
    if (n < need || !pts->p) {
        fs_error(FS_ERR_DATA, "delaunay: %d points: a %s needs at least %d", (int)n, fs_domain_type_name(dom.type),
                 (int)need);
        return -1;
    }
    for (int64_t k = 0; k < 3 * (int64_t)n; k++) {
        if (!isfinite(pts->p[k])) {
            fs_error(FS_ERR_DATA, "delaunay: point %d has a coordinate that is not a finite number", (int)(k / 3));
            return -1;
        }
    }
    bool periodic = dom.type == FS_DOMAIN_CYLINDER || (dom.type == FS_DOMAIN_PLANE && (dom.periodic_x || dom.periodic_y));
    out->domain = dom;
    out->n_nodes = n;
    out->pos = fs_malloc(3 * (size_t)n * sizeof *out->pos);
    memcpy(out->pos, pts->p, 3 * (size_t)n * sizeof *out->pos);
    if (periodic)
        for (int32_t i = 0; i < n; i++)
            fs_domain_wrap(&dom, out->pos + 3 * (size_t)i);

    int32_t i, j;
    if (find_duplicate(out->pos, n, &i, &j)) {
        fs_error(FS_ERR_DATA, "delaunay: points %d and %d coincide%s", (int)i, (int)j,
                 periodic ? " (modulo the period)" : "");
        fs_mesh_free(out);
        return -1;
    }
    int rc = dom.type == FS_DOMAIN_SPHERE ? triangulate_sphere(out) : triangulate_2d(out);
    if (rc != 0)
        fs_mesh_free(out);
    return rc;
}

/* ---- 3-D Delaunay (tetrahedral layers) ---- */

void fs_tets_free(fs_tets *t)
{
    free(t->tet);
    free(t->shift);
    memset(t, 0, sizeof *t);
}

/* design: the periodic 3-D triangulation follows the 2-D one (run_block): every point and its images
 * across the wrapping sides within `margin` of the fundamental cell are triangulated together, a
 * tetrahedron's corners are (node, image shift), its copies differ by a common shift, and the one copy
 * whose smallest corner (node, then shift) has shift (0, 0) is kept. Without `merge` Qhull runs
 * without facet merging first (see run_qhull; on layered points, whose layers make large flat hull
 * faces, merging is twenty times slower), and with merging when that fails. Whether the margin was
 * wide enough, and the result valid, is the caller's check (geom/tetmesh.c checks the faces and the volume and retries wider).
 * Tetrahedra are turned positive; flat ones (zero volume, from cospherical ties) are kept, so that
 * the faces still match, and left to the caller. */
int fs_delaunay_tets(const double *pts, int32_t n, const double period[2], double margin, bool merge, fs_tets *out)
{
    memset(out, 0, sizeof *out);
    if (n < 4 || !pts) {
        fs_error(FS_ERR_DATA, "delaunay: %d points: a tetrahedral mesh needs at least 4", (int)n);
        return -1;
    }
    for (int64_t k = 0; k < 3 * (int64_t)n; k++)
        if (!isfinite(pts[k])) {
            fs_error(FS_ERR_DATA, "delaunay: point %d has a coordinate that is not a finite number", (int)(k / 3));
            return -1;
        }
    bool wraps[2] = {period[0] > 0.0, period[1] > 0.0};
    int kr[2] = {wraps[0] ? 1 : 0, wraps[1] ? 1 : 0};
    /* images: node and shift of each point fed to Qhull */
    size_t cap = (size_t)n * (size_t)((2 * kr[0] + 1) * (2 * kr[1] + 1));
    double *xyz = fs_malloc(3 * cap * sizeof *xyz);
    int32_t *img_node = fs_malloc(cap * sizeof *img_node);
    int8_t *img_shift = fs_malloc(2 * cap * sizeof *img_shift);
    size_t count = 0;
    for (int pass = 0; pass < 2; pass++) /* the originals first, so that ids below n are the nodes */
        for (int32_t i = 0; i < n; i++)
            for (int sx = -kr[0]; sx <= kr[0]; sx++)
                for (int sy = -kr[1]; sy <= kr[1]; sy++) {
                    bool original = sx == 0 && sy == 0;
                    if (original != (pass == 0))
                        continue;
                    double p[3] = {pts[3 * (size_t)i] + sx * period[0], pts[3 * (size_t)i + 1] + sy * period[1],
                                   pts[3 * (size_t)i + 2]};
                    bool keep = true;
                    for (int d = 0; d < 2; d++)
                        if (wraps[d] && (p[d] < -margin || p[d] >= period[d] + margin))
                            keep = false;
                    if (!keep)
                        continue;
                    memcpy(xyz + 3 * count, p, sizeof p);
                    img_node[count] = i;
                    img_shift[2 * count] = (int8_t)sx;
                    img_shift[2 * count + 1] = (int8_t)sy;
                    count++;
                }
    int32_t *raw = NULL;
    int64_t nraw = 0;
    int rc = -1;
    if (count > INT32_MAX)
        fs_error(FS_ERR_DATA, "delaunay: %zu points with their periodic images are too many", count);
    else if ((rc = run_qhull(3, (int32_t)count, xyz, true, merge, &raw, &nraw)) < 0 && !merge)
        rc = run_qhull(3, (int32_t)count, xyz, true, true, &raw, &nraw);
    if (rc == 0) {
        out->tet = fs_malloc((size_t)(nraw ? nraw : 1) * 4 * sizeof *out->tet);
        out->shift = fs_malloc((size_t)(nraw ? nraw : 1) * 8 * sizeof *out->shift);
        int64_t kept = 0;
        for (int64_t t = 0; t < nraw; t++) {
            const int32_t *v = raw + 4 * t;
            int first = 0;
            for (int c = 1; c < 4; c++)
                if (corner_less(img_node[v[c]], img_shift + 2 * (size_t)v[c], img_node[v[first]],
                                    img_shift + 2 * (size_t)v[first]))
                    first = c;
            if (img_shift[2 * (size_t)v[first]] != 0 || img_shift[2 * (size_t)v[first] + 1] != 0)
                continue;
            int32_t *tv = out->tet + 4 * kept;
            int8_t *ts = out->shift + 8 * kept;
            for (int c = 0; c < 4; c++) {
                tv[c] = img_node[v[c]];
                ts[2 * c] = img_shift[2 * (size_t)v[c]];
                ts[2 * c + 1] = img_shift[2 * (size_t)v[c] + 1];
            }
            const double *a = xyz + 3 * (size_t)v[0];
            double e[3][3];
            for (int c = 0; c < 3; c++)
                fs_sub3(e[c], xyz + 3 * (size_t)v[c + 1], a);
            double cr[3];
            fs_cross3(cr, e[0], e[1]);
            if (fs_dot3(cr, e[2]) < 0.0) {
                int32_t sv = tv[2];
                tv[2] = tv[3];
                tv[3] = sv;
                int8_t s0 = ts[4], s1 = ts[5];
                ts[4] = ts[6];
                ts[5] = ts[7];
                ts[6] = s0;
                ts[7] = s1;
            }
            kept++;
        }
        if (kept > INT32_MAX / 4) {
            fs_error(FS_ERR_DATA, "delaunay: %lld tetrahedra are too many", (long long)kept);
            fs_tets_free(out);
            rc = -1;
        } else {
            out->n_tets = (int32_t)kept;
        }
    }
    free(raw);
    free(xyz);
    free(img_node);
    free(img_shift);
    return rc;
}
