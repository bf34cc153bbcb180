/* Reading a UV-mapped OBJ mesh, welding it by position and refusing what a model cannot take. */
#include "geom/uvmesh.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"

/* Texture coordinates this far outside [0, 1] are refused; overlaps this deep are refused. */
#define UV_SLACK 1e-6
#define UV_OVERLAP 1e-9
#define UV_MIN_AREA 1e-12

/* Largest file read, in bytes (far beyond any mesh under FS_UVMESH_MAX_TRIS). */
#define MAX_FILE_BYTES ((size_t)1 << 30)

typedef struct {
    const char *name;
    double *v;        /* 3 per position */
    int32_t nv, cv;
    double *vt;       /* 2 per texture coordinate */
    int32_t nvt, cvt;
    int32_t *corner;  /* per triangle: 3 (position, texture) pairs = 6 */
    int32_t *line;    /* per triangle: the line of its face */
    int32_t nt, ct;
} obj;

static void *grow(void *a, int32_t *cap, int32_t need, size_t size)
{
    if (need <= *cap)
        return a;
    int32_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    *cap = c;
    return fs_realloc(a, (size_t)c * size);
}

static void obj_free(obj *o)
{
    free(o->v);
    free(o->vt);
    free(o->corner);
    free(o->line);
}

/* Reads up to n doubles after the keyword; returns how many. */
static int read_numbers(const char *s, const char *end, double *out, int n)
{
    int k = 0;
    while (k < n) {
        while (s < end && (*s == ' ' || *s == '\t'))
            s++;
        if (s >= end)
            break;
        char buf[64];
        size_t len = 0;
        while (s < end && *s != ' ' && *s != '\t' && len < sizeof buf - 1)
            buf[len++] = *s++;
        buf[len] = '\0';
        char *stop;
        errno = 0;
        double v = strtod(buf, &stop);
        if (*stop != '\0' || errno == ERANGE || !isfinite(v))
            return -1 - k;
        out[k++] = v;
    }
    return k;
}

/* One index of a face corner: 1-based, or negative from the end; 0 for none (empty). Returns the
 * 0-based index, -1 for none, -2 for a bad one. */
static int32_t parse_index(const char *s, size_t len, int32_t count)
{
    if (len == 0)
        return -1;
    char buf[32];
    if (len >= sizeof buf)
        return -2;
    memcpy(buf, s, len);
    buf[len] = '\0';
    char *stop;
    errno = 0;
    long v = strtol(buf, &stop, 10);
    if (*stop != '\0' || errno == ERANGE || v == 0)
        return -2;
    if (v < 0)
        v += count + 1;
    if (v < 1 || v > count)
        return -2;
    return (int32_t)(v - 1);
}

static int fail(const char *name, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(const char *name, int line, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (line > 0)
        fs_error(FS_ERR_DATA, "%s:%d: %s", name, line, msg);
    else
        fs_error(FS_ERR_DATA, "%s: %s", name, msg);
    return -1;
}

/* A face line: its corners into fan triangles. */
static int parse_face(obj *o, const char *s, const char *end, int line)
{
    int32_t cv[64], ct[64];
    int n = 0;
    while (1) {
        while (s < end && (*s == ' ' || *s == '\t'))
            s++;
        if (s >= end)
            break;
        const char *tok = s;
        while (s < end && *s != ' ' && *s != '\t')
            s++;
        if (n == 64)
            return fail(o->name, line, "a face of more than 64 corners");
        const char *slash1 = memchr(tok, '/', (size_t)(s - tok));
        const char *vend = slash1 ? slash1 : s;
        int32_t iv = parse_index(tok, (size_t)(vend - tok), o->nv);
        if (iv < 0)
            return fail(o->name, line, "corner %d: expected the index of a vertex defined above, got '%.*s'", n + 1,
                        (int)(s - tok), tok);
        int32_t it = -1;
        if (slash1) {
            const char *t0 = slash1 + 1;
            const char *slash2 = memchr(t0, '/', (size_t)(s - t0));
            const char *tend = slash2 ? slash2 : s;
            it = parse_index(t0, (size_t)(tend - t0), o->nvt);
            if (it == -2)
                return fail(o->name, line, "corner %d: expected the index of a texture coordinate defined above, got "
                            "'%.*s'", n + 1, (int)(s - tok), tok);
        }
        if (it < 0)
            return fail(o->name, line, "corner %d has no texture coordinate: the mesh needs UVs (faces v/vt or v/vt/vn)",
                        n + 1);
        cv[n] = iv;
        ct[n] = it;
        n++;
    }
    if (n < 3)
        return fail(o->name, line, "a face needs at least 3 corners, got %d", n);
    for (int k = 1; k + 1 < n; k++) {
        if (o->nt >= FS_UVMESH_MAX_TRIS)
            return fail(o->name, line, "more than %d triangles: the largest mesh taken (split it, or decimate it)",
                        FS_UVMESH_MAX_TRIS);
        int32_t cap = o->ct;
        o->corner = grow(o->corner, &cap, o->nt + 1, 6 * sizeof *o->corner);
        o->line = grow(o->line, &o->ct, o->nt + 1, sizeof *o->line);
        int32_t *c = o->corner + 6 * (size_t)o->nt;
        int idx[3] = {0, k, k + 1};
        for (int q = 0; q < 3; q++) {
            c[2 * q] = cv[idx[q]];
            c[2 * q + 1] = ct[idx[q]];
        }
        o->line[o->nt++] = line;
    }
    return 0;
}

static int parse_text(obj *o, const char *text, size_t len)
{
    const char *p = text, *stop = text + len;
    int line = 0;
    while (p < stop) {
        const char *eol = memchr(p, '\n', (size_t)(stop - p));
        const char *end = eol ? eol : stop;
        line++;
        const char *s = p;
        p = eol ? eol + 1 : stop;
        if (end > s && end[-1] == '\r')
            end--;
        while (s < end && (*s == ' ' || *s == '\t'))
            s++;
        if (s >= end || *s == '#')
            continue;
        const char *kw = s;
        while (s < end && *s != ' ' && *s != '\t')
            s++;
        size_t kl = (size_t)(s - kw);
        if (kl == 1 && kw[0] == 'v') {
            double x[3];
            if (read_numbers(s, end, x, 3) != 3)
                return fail(o->name, line, "expected 'v x y z' with three numbers");
            o->v = grow(o->v, &o->cv, o->nv + 1, 3 * sizeof *o->v);
            memcpy(o->v + 3 * (size_t)o->nv++, x, sizeof x);
        } else if (kl == 2 && kw[0] == 'v' && kw[1] == 't') {
            double t[2];
            if (read_numbers(s, end, t, 2) != 2)
                return fail(o->name, line, "expected 'vt u v' with two numbers");
            o->vt = grow(o->vt, &o->cvt, o->nvt + 1, 2 * sizeof *o->vt);
            memcpy(o->vt + 2 * (size_t)o->nvt++, t, sizeof t);
        } else if (kl == 1 && kw[0] == 'f') {
            if (parse_face(o, s, end, line) < 0)
                return -1;
        }
        /* other statements (vn, o, g, s, usemtl, mtllib, l, p) do not matter */
    }
    if (o->nt == 0)
        return fail(o->name, 0, "no faces: expected a triangle mesh with texture coordinates");
    return 0;
}

/* ---- welding ---- */

static const double *sort_pos;

static int cmp_pos(const void *a, const void *b)
{
    int32_t i = *(const int32_t *)a, j = *(const int32_t *)b;
    for (int k = 0; k < 3; k++) {
        double x = sort_pos[3 * (size_t)i + k], y = sort_pos[3 * (size_t)j + k];
        if (x < y)
            return -1;
        if (x > y)
            return 1;
    }
    return i < j ? -1 : i > j;
}

/* Maps every used position to a welded vertex (equal coordinates are one), numbered in the order of
 * their first use by the faces. Returns the vertex count; weld[i] = -1 for unused positions. */
static int32_t weld_positions(const obj *o, int32_t *weld)
{
    int32_t *order = fs_malloc(((size_t)o->nv + 1) * sizeof *order);
    int32_t *rep = fs_malloc(((size_t)o->nv + 1) * sizeof *rep);
    for (int32_t i = 0; i < o->nv; i++)
        order[i] = i;
    sort_pos = o->v;
    qsort(order, (size_t)o->nv, sizeof *order, cmp_pos);
    for (int32_t k = 0; k < o->nv; k++) {
        int32_t i = order[k];
        rep[i] = i;
        if (k > 0) {
            int32_t j = order[k - 1];
            if (!memcmp(o->v + 3 * (size_t)i, o->v + 3 * (size_t)j, 3 * sizeof(double)))
                rep[i] = rep[j];
        }
    }
    for (int32_t i = 0; i < o->nv; i++)
        weld[i] = -1;
    int32_t n = 0;
    for (int32_t t = 0; t < o->nt; t++)
        for (int c = 0; c < 3; c++) {
            int32_t r = rep[o->corner[6 * (size_t)t + 2 * c]];
            if (weld[r] < 0)
                weld[r] = n++;
        }
    for (int32_t i = 0; i < o->nv; i++)
        weld[i] = weld[rep[i]];
    free(order);
    free(rep);
    return n;
}

/* ---- checks ---- */

typedef struct {
    int32_t a, b;  /* smaller, larger vertex */
    int32_t tri;
    int8_t dir;    /* 1 if the triangle runs a -> b */
} edge_use;

static int cmp_edge(const void *x, const void *y)
{
    const edge_use *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->tri < q->tri ? -1 : p->tri > q->tri;
}

static int check_edges(const obj *o, const fs_mesh *m)
{
    size_t n = 3 * (size_t)m->n_tris;
    edge_use *e = fs_malloc((n + 1) * sizeof *e);
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int c = 0; c < 3; c++) {
            int32_t u = m->tri[3 * (size_t)t + c], v = m->tri[3 * (size_t)t + (c + 1) % 3];
            e[3 * (size_t)t + c] = (edge_use){u < v ? u : v, u < v ? v : u, t, (int8_t)(u < v)};
        }
    qsort(e, n, sizeof *e, cmp_edge);
    int rc = 0;
    for (size_t i = 0; i < n && rc == 0;) {
        size_t j = i;
        while (j < n && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        const double *pa = m->pos + 3 * (size_t)e[i].a, *pb = m->pos + 3 * (size_t)e[i].b;
        if (j - i > 2)
            rc = fail(o->name, 0, "non-manifold edge from (%g, %g, %g) to (%g, %g, %g): %d faces share it (lines %d, %d, "
                      "%d)", pa[0], pa[1], pa[2], pb[0], pb[1], pb[2], (int)(j - i), (int)o->line[e[i].tri],
                      (int)o->line[e[i + 1].tri], (int)o->line[e[i + 2].tri]);
        else if (j - i == 2 && e[i].dir == e[i + 1].dir)
            rc = fail(o->name, 0, "the faces of lines %d and %d run along their shared edge the same way: the faces are "
                      "not consistently oriented (or the surface is non-orientable)", (int)o->line[e[i].tri],
                      (int)o->line[e[i + 1].tri]);
        i = j;
    }
    free(e);
    return rc;
}

/* Every vertex's faces form one fan (a disc or a half-disc): walking across edges around the vertex
 * from one of its faces reaches them all. Requires adjacency. */
static int check_vertex_fans(const obj *o, const fs_mesh *m)
{
    int32_t nv = m->n_nodes;
    int32_t *start = fs_calloc((size_t)nv + 1, sizeof *start);
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int c = 0; c < 3; c++)
            start[m->tri[3 * (size_t)t + c] + 1]++;
    for (int32_t v = 0; v < nv; v++)
        start[v + 1] += start[v];
    int32_t *first = fs_malloc(((size_t)nv + 1) * sizeof *first);
    for (int32_t v = 0; v < nv; v++)
        first[v] = -1;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int c = 0; c < 3; c++) {
            int32_t v = m->tri[3 * (size_t)t + c];
            if (first[v] < 0)
                first[v] = t;
        }
    int rc = 0;
    for (int32_t v = 0; v < nv && rc == 0; v++) {
        int32_t degree = start[v + 1] - start[v], seen = 1;
        /* walk both ways from the first face */
        for (int way = 0; way < 2; way++) {
            int32_t t = first[v];
            for (int32_t steps = 0; steps < degree; steps++) {
                int c = fs_mesh_corner_of(m, t, v);
                /* way 0 leaves across the edge after the corner's (c, c+1), way 1 the one before (c-1, c) */
                int32_t next = m->adj[3 * (size_t)t + (way == 0 ? c : (c + 2) % 3)];
                if (next < 0 || next == first[v])
                    break;
                t = next;
                seen++;
            }
            if (seen >= degree)
                break;
        }
        if (seen < degree) {
            const double *p = m->pos + 3 * (size_t)v;
            rc = fail(o->name, 0, "non-manifold vertex at (%g, %g, %g): its %d faces do not form one fan (line %d)",
                      p[0], p[1], p[2], (int)degree, (int)o->line[first[v]]);
        }
    }
    free(start);
    free(first);
    return rc;
}

/* Whether the projections of the two texture triangles onto the normals of their edges overlap by
 * more than UV_OVERLAP on every axis (separating axes: no overlap if any axis separates them). */
static bool uv_overlap(const double *a, const double *b)
{
    const double *tri[2] = {a, b};
    for (int w = 0; w < 2; w++)
        for (int i = 0; i < 3; i++) {
            const double *p = tri[w] + 2 * i, *q = tri[w] + 2 * ((i + 1) % 3);
            double nx = q[1] - p[1], ny = p[0] - q[0], l = hypot(nx, ny);
            if (!(l > 0.0))
                continue;
            nx /= l, ny /= l;
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int u = 0; u < 2; u++)
                for (int k = 0; k < 3; k++) {
                    double d = tri[u][2 * k] * nx + tri[u][2 * k + 1] * ny;
                    lo[u] = fmin(lo[u], d);
                    hi[u] = fmax(hi[u], d);
                }
            if (fmin(hi[0], hi[1]) - fmax(lo[0], lo[1]) <= UV_OVERLAP)
                return false;
        }
    return true;
}

static int check_uv_overlaps(const obj *o, const double *uv, int32_t nt)
{
    int g = (int)ceil(sqrt((double)nt));
    g = g < 1 ? 1 : g > 1024 ? 1024 : g;
    int32_t *box = fs_malloc(4 * ((size_t)nt + 1) * sizeof *box);
    int32_t *count = fs_calloc((size_t)g * g + 1, sizeof *count);
    for (int32_t t = 0; t < nt; t++) {
        const double *u = uv + 6 * (size_t)t;
        double lo[2] = {fmin(fmin(u[0], u[2]), u[4]), fmin(fmin(u[1], u[3]), u[5])};
        double hi[2] = {fmax(fmax(u[0], u[2]), u[4]), fmax(fmax(u[1], u[3]), u[5])};
        int32_t *b = box + 4 * (size_t)t;
        for (int k = 0; k < 2; k++) {
            int l = (int)floor(lo[k] * g), h = (int)floor(hi[k] * g);
            b[k] = l < 0 ? 0 : l >= g ? g - 1 : l;
            b[2 + k] = h < 0 ? 0 : h >= g ? g - 1 : h;
        }
        for (int y = b[1]; y <= b[3]; y++)
            for (int x = b[0]; x <= b[2]; x++)
                count[(size_t)y * g + x + 1]++;
    }
    for (size_t c = 0; c < (size_t)g * g; c++)
        count[c + 1] += count[c];
    int32_t *cell = fs_malloc(((size_t)count[(size_t)g * g] + 1) * sizeof *cell);
    int32_t *fill = fs_malloc(((size_t)g * g + 1) * sizeof *fill);
    memcpy(fill, count, (size_t)g * g * sizeof *fill);
    for (int32_t t = 0; t < nt; t++) {
        const int32_t *b = box + 4 * (size_t)t;
        for (int y = b[1]; y <= b[3]; y++)
            for (int x = b[0]; x <= b[2]; x++)
                cell[fill[(size_t)y * g + x]++] = t;
    }
    int rc = 0;
    for (int y = 0; y < g && rc == 0; y++)
        for (int x = 0; x < g && rc == 0; x++) {
            size_t c = (size_t)y * g + x;
            for (int32_t p = count[c]; p < count[c + 1] && rc == 0; p++)
                for (int32_t q = p + 1; q < count[c + 1]; q++) {
                    int32_t s = cell[p], t = cell[q];
                    const int32_t *bs = box + 4 * (size_t)s, *bt = box + 4 * (size_t)t;
                    /* test each pair once: in the first cell both boxes share */
                    int fx = bs[0] > bt[0] ? bs[0] : bt[0], fy = bs[1] > bt[1] ? bs[1] : bt[1];
                    if (fx != x || fy != y)
                        continue;
                    if (uv_overlap(uv + 6 * (size_t)s, uv + 6 * (size_t)t)) {
                        rc = fail(o->name, 0, "the texture coordinates of the faces of lines %d and %d overlap: each "
                                  "point of the maps must belong to one place of the surface", (int)o->line[s < t ? s : t],
                                  (int)o->line[s < t ? t : s]);
                        break;
                    }
                }
        }
    free(box);
    free(count);
    free(cell);
    free(fill);
    return rc;
}

int fs_uvmesh_parse(const char *text, size_t len, const char *name, fs_mesh *out, double **corner_uv)
{
    memset(out, 0, sizeof *out);
    *corner_uv = NULL;
    obj o;
    memset(&o, 0, sizeof o);
    o.name = name;
    if (parse_text(&o, text, len) < 0) {
        obj_free(&o);
        return -1;
    }
    int32_t *weld = fs_malloc(((size_t)o.nv + 1) * sizeof *weld);
    int32_t nv = weld_positions(&o, weld);
    fs_mesh m;
    memset(&m, 0, sizeof m);
    m.domain.type = FS_DOMAIN_MESH;
    m.n_nodes = nv;
    m.pos = fs_malloc(3 * ((size_t)nv + 1) * sizeof *m.pos);
    for (int32_t i = 0; i < o.nv; i++)
        if (weld[i] >= 0)
            memcpy(m.pos + 3 * (size_t)weld[i], o.v + 3 * (size_t)i, 3 * sizeof *m.pos);
    m.n_tris = o.nt;
    m.tri = fs_malloc(3 * (size_t)o.nt * sizeof *m.tri);
    m.shift = fs_calloc(6 * (size_t)o.nt, sizeof *m.shift);
    m.adj = fs_malloc(3 * (size_t)o.nt * sizeof *m.adj);
    double *uv = fs_malloc(6 * (size_t)o.nt * sizeof *uv);
    double area = 0.0, uv_area = 0.0;
    int rc = 0;
    for (int32_t t = 0; t < o.nt && rc == 0; t++) {
        const int32_t *c = o.corner + 6 * (size_t)t;
        double p[3][3];
        for (int k = 0; k < 3; k++) {
            m.tri[3 * (size_t)t + k] = weld[c[2 * k]];
            memcpy(p[k], o.v + 3 * (size_t)c[2 * k], sizeof p[k]);
            uv[6 * (size_t)t + 2 * k] = o.vt[2 * (size_t)c[2 * k + 1]];
            uv[6 * (size_t)t + 2 * k + 1] = o.vt[2 * (size_t)c[2 * k + 1] + 1];
        }
        const int32_t *v = m.tri + 3 * (size_t)t;
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            rc = fail(name, o.line[t], "degenerate triangle: two of its corners are the same vertex");
            break;
        }
        double d1[3], d2[3], n[3];
        fs_sub3(d1, p[1], p[0]);
        fs_sub3(d2, p[2], p[0]);
        fs_cross3(n, d1, d2);
        double lmax = fmax(fmax(fs_dot3(d1, d1), fs_dot3(d2, d2)), 1e-300);
        if (!(fs_norm3(n) > 1e-12 * lmax)) {
            rc = fail(name, o.line[t], "degenerate triangle: its corners are on one line (no area)");
            break;
        }
        area += 0.5 * fs_norm3(n);
        const double *u = uv + 6 * (size_t)t;
        for (int k = 0; k < 6 && rc == 0; k++)
            if (!(u[k] >= -UV_SLACK && u[k] <= 1.0 + UV_SLACK))
                rc = fail(name, o.line[t], "texture coordinate %g is outside [0, 1]: the maps cover the unit square only",
                          u[k]);
        double ua = 0.5 * ((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
        if (rc == 0 && !(fabs(ua) >= UV_MIN_AREA))
            rc = fail(name, o.line[t], "degenerate texture coordinates: the triangle has no area in the UV layout");
        uv_area += fabs(ua);
    }
    if (rc == 0)
        rc = check_edges(&o, &m);
    if (rc == 0 && fs_mesh_build_adjacency(&m) < 0)
        rc = fail(name, 0, "non-manifold edge: more than two faces share it");
    if (rc == 0)
        rc = check_vertex_fans(&o, &m);
    if (rc == 0)
        rc = check_uv_overlaps(&o, uv, o.nt);
    free(weld);
    obj_free(&o);
    if (rc < 0) {
        fs_mesh_free(&m);
        free(uv);
        return -1;
    }
    m.domain.width = m.domain.height = sqrt(area / uv_area);
    fs_mesh_build_edges(&m);
    fs_mesh_build_rings(&m);
    *out = m;
    *corner_uv = uv;
    return 0;
}

int fs_uvmesh_read(const char *path, fs_mesh *out, double **corner_uv)
{
    memset(out, 0, sizeof *out);
    *corner_uv = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        fs_error(errno == ENOENT ? FS_ERR_NOINPUT : FS_ERR_IO, "%s: cannot open the mesh: %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 1 << 16, len = 0;
    char *text = fs_malloc(cap);
    while (1) {
        if (len == cap) {
            if (cap >= MAX_FILE_BYTES) {
                fclose(f);
                free(text);
                return fail(path, 0, "larger than %zu bytes: the largest mesh taken has %d triangles", MAX_FILE_BYTES,
                            FS_UVMESH_MAX_TRIS);
            }
            cap *= 2;
            text = fs_realloc(text, cap);
        }
        size_t got = fread(text + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(text);
        fs_error(FS_ERR_IO, "%s: read error", path);
        return -1;
    }
    int rc = fs_uvmesh_parse(text, len, path, out, corner_uv);
    free(text);
    return rc;
}
