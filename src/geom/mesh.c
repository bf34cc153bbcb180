/* Triangle meshes on a domain: adjacency, edges, vertex rings, and the Voronoi dual. */
#include "geom/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/threads.h"
#include "base/uf.h"
#include "base/vec.h"

/* Period of the domain along x / y, or 0 in a direction that does not wrap. */
static double period_x(const fs_mesh *m)
{
    bool wraps = m->domain.type == FS_DOMAIN_CYLINDER || (m->domain.type == FS_DOMAIN_PLANE && m->domain.periodic_x);
    return wraps ? fs_domain_extent_x(&m->domain) : 0.0;
}

static double period_y(const fs_mesh *m)
{
    return m->domain.type != FS_DOMAIN_SPHERE && m->domain.periodic_y ? fs_domain_extent_y(&m->domain) : 0.0;
}

void fs_mesh_free(fs_mesh *m)
{
    free(m->pos);
    free(m->tri);
    free(m->shift);
    free(m->adj);
    free(m->edge);
    free(m->edge_tri);
    free(m->tri_edge);
    free(m->ring_start);
    free(m->ring_tri);
    memset(m, 0, sizeof *m);
}

void fs_mesh_corner(const fs_mesh *m, int32_t t, int c, double *out)
{
    const double *p = m->pos + 3 * (size_t)m->tri[3 * (size_t)t + c];
    out[0] = p[0];
    out[1] = p[1];
    out[2] = p[2];
    if (m->shift) {
        const int8_t *s = m->shift + 6 * (size_t)t + 2 * c;
        if (s[0])
            out[0] += s[0] * period_x(m);
        if (s[1])
            out[1] += s[1] * period_y(m);
    }
}

double fs_mesh_tri_area(const fs_mesh *m, int32_t t)
{
    double a[3], b[3], c[3];
    fs_mesh_corner(m, t, 0, a);
    fs_mesh_corner(m, t, 1, b);
    fs_mesh_corner(m, t, 2, c);
    if (m->domain.type != FS_DOMAIN_SPHERE)
        return 0.5 * fs_orient2(a, b, c);
    double ab[3], ac[3], n[3], centroid[3];
    fs_sub3(ab, b, a);
    fs_sub3(ac, c, a);
    fs_cross3(n, ab, ac);
    for (int k = 0; k < 3; k++)
        centroid[k] = a[k] + b[k] + c[k];
    double area = 0.5 * fs_norm3(n);
    return fs_dot3(n, centroid) >= 0.0 ? area : -area;
}

int32_t fs_mesh_count_boundary_edges(const fs_mesh *m)
{
    int32_t count = 0;
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        count += m->adj[h] < 0;
    return count;
}

/* FNV-1a over n bytes, continuing from h. */
static uint64_t digest_bytes(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; b && i < n; i++)
        h = (h ^ b[i]) * UINT64_C(0x100000001b3);
    return h;
}

uint64_t fs_mesh_digest(const fs_mesh *m)
{
    size_t nt = (size_t)m->n_tris, ne = (size_t)m->n_edges;
    uint64_t h = UINT64_C(0xcbf29ce484222325);
    h = digest_bytes(h, m->pos, 3 * (size_t)m->n_nodes * sizeof *m->pos);
    h = digest_bytes(h, m->tri, 3 * nt * sizeof *m->tri);
    h = digest_bytes(h, m->shift, 6 * nt * sizeof *m->shift);
    h = digest_bytes(h, m->adj, 3 * nt * sizeof *m->adj);
    h = digest_bytes(h, m->edge, 2 * ne * sizeof *m->edge);
    h = digest_bytes(h, m->edge_tri, 2 * ne * sizeof *m->edge_tri);
    h = digest_bytes(h, m->tri_edge, 3 * nt * sizeof *m->tri_edge);
    if (m->ring_start) {
        h = digest_bytes(h, m->ring_start, ((size_t)m->n_nodes + 1) * sizeof *m->ring_start);
        h = digest_bytes(h, m->ring_tri, (size_t)m->ring_start[m->n_nodes] * sizeof *m->ring_tri);
    }
    return h;
}

/* Half-edge h = 3 t + i runs from corner i to corner (i + 1) % 3 of triangle t: its nodes, and the
 * image offset of its end relative to its start (zero off the seams). */
typedef struct {
    int32_t from, to;
    int dx, dy;
} half_edge;

static half_edge half_edge_of(const fs_mesh *m, int32_t h)
{
    int32_t t = h / 3;
    int i = h % 3, j = (i + 1) % 3;
    half_edge e = {m->tri[h], m->tri[3 * t + j], 0, 0};
    if (m->shift) {
        e.dx = m->shift[6 * t + 2 * j] - m->shift[6 * t + 2 * i];
        e.dy = m->shift[6 * t + 2 * j + 1] - m->shift[6 * t + 2 * i + 1];
    }
    return e;
}

static bool same_direction(half_edge g, half_edge h)
{
    return g.from == h.from && g.to == h.to && g.dx == h.dx && g.dy == h.dy;
}

static bool opposite(half_edge g, half_edge h)
{
    return g.from == h.to && g.to == h.from && g.dx == -h.dx && g.dy == -h.dy;
}

/* The half-edge running the other way along the same edge, or -1 on a boundary. */
static int32_t partner(const fs_mesh *m, int32_t h)
{
    int32_t u = m->adj[h];
    if (u < 0)
        return -1;
    half_edge e = half_edge_of(m, h);
    for (int j = 0; j < 3; j++) {
        int32_t g = 3 * u + j;
        if (g != h && m->tri[g] == e.to && m->adj[g] == h / 3 && opposite(half_edge_of(m, g), e))
            return g;
    }
    return -1;
}

/* Half-edges grouped by their start node (counting sort, CSR): start has n_nodes + 1 entries. The
 * same lists are the corners of each node, in ascending order: half-edge 3 t + c starts at corner c. */
static void node_half_edges(const fs_mesh *m, int32_t **start_out, int32_t **list_out)
{
    int32_t nh = 3 * m->n_tris;
    int32_t *start = fs_calloc((size_t)m->n_nodes + 1, sizeof *start);
    for (int32_t h = 0; h < nh; h++)
        start[m->tri[h] + 1]++;
    for (int32_t v = 0; v < m->n_nodes; v++)
        start[v + 1] += start[v];
    int32_t *fill = fs_malloc(((size_t)m->n_nodes + 1) * sizeof *fill);
    memcpy(fill, start, ((size_t)m->n_nodes + 1) * sizeof *fill);
    int32_t *list = fs_malloc((size_t)(nh ? nh : 1) * sizeof *list);
    for (int32_t h = 0; h < nh; h++)
        list[fill[m->tri[h]]++] = h;
    free(fill);
    *start_out = start;
    *list_out = list;
}

/* A key with its value, for sorting the keys of a node of high degree. */
typedef struct {
    uint64_t key;
    int32_t val;
} keyed;

static int keyed_cmp(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->val > b->val) - (a->val < b->val);
}

/* Sorts the keys of each of n nodes (with their values, ascending on entry) in place, stably: the
 * keys of node i are key[start[i] - base .. start[i + 1] - base), all with the same node in their
 * high bits. An insertion sort of a node's few keys; a sort by key and value (the same order) for a
 * node of high degree. */
static void sort_node_runs(uint64_t *key, int32_t *val, const int32_t *start, int32_t n, int32_t base)
{
    for (int32_t v = 0; v < n; v++) {
        int32_t i0 = start[v] - base, i1 = start[v + 1] - base;
        if (i1 - i0 > 32) {
            keyed *kv = fs_malloc((size_t)(i1 - i0) * sizeof *kv);
            for (int32_t i = i0; i < i1; i++)
                kv[i - i0] = (keyed){key[i], val[i]};
            qsort(kv, (size_t)(i1 - i0), sizeof *kv, keyed_cmp);
            for (int32_t i = i0; i < i1; i++) {
                key[i] = kv[i - i0].key;
                val[i] = kv[i - i0].val;
            }
            free(kv);
            continue;
        }
        for (int32_t i = i0 + 1; i < i1; i++) {
            uint64_t k = key[i];
            int32_t x = val[i], p = i;
            for (; p > i0 && key[p - 1] > k; p--) {
                key[p] = key[p - 1];
                val[p] = val[p - 1];
            }
            key[p] = k;
            val[p] = x;
        }
    }
}

/* Pairs the half-edges val[0 .. n) (their adj entries -1 on entry) whose keys (see below) key[] holds,
 * sorted; shifted: the mesh has image offsets. Returns 0, or -1 with fs_error for a non-manifold
 * edge. */
static int pair_sorted(fs_mesh *m, const uint64_t *key, const int32_t *val, int32_t n, bool shifted)
{
    for (int32_t i = 0; i < n;) {
        int32_t j = i + 1;
        while (j < n && key[j] >> 1 == key[i] >> 1)
            j++;
        if (!shifted && j - i <= 2 && key[i] != key[j - 1]) {
            /* the common case off the seams: one half-edge each way */
            m->adj[val[i]] = val[j - 1] / 3;
            m->adj[val[j - 1]] = val[i] / 3;
            i = j;
            continue;
        }
        if (!shifted && j - i == 1) {
            i = j;
            continue;
        }
        for (int32_t p = i; p < j; p++) {
            half_edge e = half_edge_of(m, val[p]);
            for (int32_t q = p + 1; q < j; q++) {
                half_edge f = half_edge_of(m, val[q]);
                bool pair = opposite(e, f);
                if (same_direction(e, f) || (pair && (m->adj[val[p]] >= 0 || m->adj[val[q]] >= 0))) {
                    fs_error(FS_ERR_DATA,
                             "mesh: edge (%d, %d) of triangle %d is shared by more than two triangles or by two "
                             "facing opposite ways (non-manifold)",
                             (int)e.from, (int)e.to, (int)(val[p] / 3));
                    return -1;
                }
                if (pair) {
                    m->adj[val[p]] = val[q] / 3;
                    m->adj[val[q]] = val[p] / 3;
                }
            }
        }
        i = j;
    }
    return 0;
}

/* Bits for a node index of the mesh. */
static int node_bits(const fs_mesh *m)
{
    int bits = 1;
    while (bits < 31 && ((int64_t)1 << bits) < m->n_nodes)
        bits++;
    return bits;
}

/* The key of half-edge h: the two nodes, then one bit for the direction (set when running from the
 * larger). */
static uint64_t half_edge_key(const fs_mesh *m, int32_t h, int bits)
{
    uint64_t a = (uint64_t)m->tri[h], b = (uint64_t)m->tri[3 * (h / 3) + (h % 3 + 1) % 3];
    return a <= b ? ((a << bits | b) << 1) : ((b << bits | a) << 1) | 1;
}

static bool mesh_shifted(const fs_mesh *m)
{
    for (int64_t k = 0; m->shift && k < 6 * (int64_t)m->n_tris; k++)
        if (m->shift[k] != 0)
            return true;
    return false;
}

/* Below this many half-edges the whole-mesh passes run on the calling thread. */
#define MESH_PARALLEL_MIN 300000
/* Most parts a whole-mesh pass is cut into (each part of a counting sort has its own counters). */
#define MESH_MAX_PARTS 8

/* Parts (one per thread, at most MESH_MAX_PARTS) for a whole-mesh pass over nh half-edges. */
static int mesh_parts(int32_t nh, int32_t n_nodes)
{
    int parts = nh >= MESH_PARALLEL_MIN ? fs_threads() : 1;
    parts = parts > MESH_MAX_PARTS ? MESH_MAX_PARTS : parts;
    return parts > n_nodes ? 1 : parts;
}

/* The shared state of fs_mesh_build_adjacency's parallel passes. */
typedef struct {
    fs_mesh *m;
    int bits, parts;
    bool shifted;
    int32_t *count;   /* parts x (n_nodes + 1): keys per smaller node of each part's half-edges, then
                       * where that part's next one goes */
    int32_t *nstart;  /* n_nodes + 1: where each node's keys start */
    uint64_t *key;    /* nh keys, sorted */
    int32_t *val;     /* their half-edges */
    int rc[MESH_MAX_PARTS];
} adjacency_build;

/* Pass 1, over part p of the half-edges: keys counted by smaller node. */
static void adjacency_count(void *ctx, int32_t p)
{
    adjacency_build *ab = ctx;
    const fs_mesh *m = ab->m;
    int32_t h0, h1, *count = ab->count + (size_t)p * ((size_t)m->n_nodes + 1);
    fs_parallel_part(3 * m->n_tris, ab->parts, p, &h0, &h1);
    for (int32_t h = h0; h < h1; h++) {
        count[half_edge_key(m, h, ab->bits) >> (ab->bits + 1)]++;
        ab->m->adj[h] = -1;
    }
}

/* Pass 2: part p's keys to their places, in half-edge order within a node (a stable sort). */
static void adjacency_scatter(void *ctx, int32_t p)
{
    adjacency_build *ab = ctx;
    const fs_mesh *m = ab->m;
    int32_t h0, h1, *next = ab->count + (size_t)p * ((size_t)m->n_nodes + 1);
    fs_parallel_part(3 * m->n_tris, ab->parts, p, &h0, &h1);
    for (int32_t h = h0; h < h1; h++) {
        uint64_t k = half_edge_key(m, h, ab->bits);
        int32_t at = next[k >> (ab->bits + 1)]++;
        ab->key[at] = k;
        ab->val[at] = h;
    }
}

/* Pass 3, over part p of the nodes: each node's keys sorted, then paired. */
static void adjacency_pair(void *ctx, int32_t p)
{
    adjacency_build *ab = ctx;
    int32_t v0, v1;
    fs_parallel_part(ab->m->n_nodes, ab->parts, p, &v0, &v1);
    int32_t i0 = ab->nstart[v0], i1 = ab->nstart[v1];
    sort_node_runs(ab->key + i0, ab->val + i0, ab->nstart + v0, v1 - v0, i0);
    ab->rc[p] = pair_sorted(ab->m, ab->key + i0, ab->val + i0, i1 - i0, ab->shifted);
}

/* design: every half-edge gets the key (smaller node, larger node, direction); a stable sort of
 * the keys (a counting sort on the smaller node, then a node's few keys: sort_node_runs) brings
 * the two half-edges of an edge together, and a run of equal node pairs is matched by image
 * offset and direction: a partner runs the other way with the opposite offset. Runs longer than
 * two are rare: tiny periodic meshes, where one pair of nodes has several edges, or a non-manifold
 * mesh. A second half-edge along the same edge in the same direction means three triangles on one
 * edge or two facing opposite ways. A large mesh is done in parts on up to fs_threads() threads:
 * the counting sort stays stable (each part counts its own half-edges, and a part's go after those
 * of the parts before it), and a run never spans two nodes, so ranges of nodes are sorted and
 * paired independently. The adjacency does not depend on the thread count; when a part finds a
 * non-manifold edge, the pairing is redone in one pass, so the error reported is the first. */
int fs_mesh_build_adjacency(fs_mesh *m)
{
    if ((int64_t)m->n_tris * 3 > INT32_MAX) {
        fs_error(FS_ERR_DATA, "mesh: %d triangles are too many", (int)m->n_tris);
        return -1;
    }
    int32_t nh = 3 * m->n_tris, nn = m->n_nodes;
    free(m->adj);
    m->adj = fs_malloc((size_t)(nh ? nh : 1) * sizeof *m->adj);
    adjacency_build ab = {.m = m, .bits = node_bits(m), .parts = mesh_parts(nh, nn), .shifted = mesh_shifted(m)};
    ab.count = fs_calloc((size_t)ab.parts * ((size_t)nn + 1), sizeof *ab.count);
    ab.nstart = fs_malloc(((size_t)nn + 1) * sizeof *ab.nstart);
    ab.key = fs_malloc((size_t)(nh ? nh : 1) * sizeof *ab.key);
    ab.val = fs_malloc((size_t)(nh ? nh : 1) * sizeof *ab.val);
    fs_parallel_for(ab.parts, ab.parts, adjacency_count, &ab);
    int32_t sum = 0;
    for (int32_t v = 0; v < nn; v++) {
        ab.nstart[v] = sum;
        for (int p = 0; p < ab.parts; p++) {
            int32_t *c = ab.count + (size_t)p * ((size_t)nn + 1) + v;
            int32_t k = *c;
            *c = sum;
            sum += k;
        }
    }
    ab.nstart[nn] = sum;
    fs_parallel_for(ab.parts, ab.parts, adjacency_scatter, &ab);
    fs_parallel_for(ab.parts, ab.parts, adjacency_pair, &ab);
    int rc = 0;
    for (int p = 0; p < ab.parts; p++)
        rc = ab.rc[p] < 0 ? -1 : rc;
    if (rc < 0 && ab.parts > 1) {
        for (int32_t h = 0; h < nh; h++)
            m->adj[h] = -1;
        rc = pair_sorted(m, ab.key, ab.val, nh, ab.shifted);
    }
    free(ab.count);
    free(ab.nstart);
    free(ab.key);
    free(ab.val);
    return rc;
}

static int cmp_keyed(const void *pa, const void *pb)
{
    return keyed_cmp(pa, pb);
}

/* design: a local change (an edge split, a node duplicated) leaves the adjacency of every triangle
 * away from it as it was. The half-edges to pair again are those of the listed and the new
 * triangles, and those of their neighbours (by the adjacency before the change) that point at a
 * listed triangle: any edge whose partner may differ has one of them on a side. They are matched
 * exactly as fs_mesh_build_adjacency matches all of them, so the result is the same. */
int fs_mesh_update_adjacency(fs_mesh *m, int32_t n_tris_before, const int32_t *changed, int32_t n_changed)
{
    if ((int64_t)m->n_tris * 3 > INT32_MAX) {
        fs_error(FS_ERR_DATA, "mesh: %d triangles are too many", (int)m->n_tris);
        return -1;
    }
    m->adj = fs_realloc(m->adj, (3 * (size_t)m->n_tris + 1) * sizeof *m->adj);
    uint8_t *dirty = fs_calloc((size_t)m->n_tris + 1, 1);
    int32_t n_dirty = 0;
    int32_t *tris = fs_malloc(((size_t)n_changed + (size_t)(m->n_tris - n_tris_before) + 1) * sizeof *tris);
    for (int32_t q = 0; q < n_changed; q++)
        if (!dirty[changed[q]]) {
            dirty[changed[q]] = 1;
            tris[n_dirty++] = changed[q];
        }
    for (int32_t t = n_tris_before; t < m->n_tris; t++) {
        dirty[t] = 1;
        tris[n_dirty++] = t;
        for (int k = 0; k < 3; k++)
            m->adj[3 * (size_t)t + k] = -1;
    }
    int32_t cap = 6 * n_dirty + 1, nh = 0;
    keyed *kv = fs_malloc((size_t)cap * sizeof *kv);
    int bits = node_bits(m);
    for (int32_t q = 0; q < n_dirty; q++) {
        int32_t t = tris[q];
        for (int k = 0; k < 3; k++) {
            int32_t h = 3 * t + k, u = m->adj[h];
            if (u >= 0 && !dirty[u])
                for (int l = 0; l < 3; l++) {
                    int32_t g = 3 * u + l;
                    if (m->adj[g] == t) {
                        m->adj[g] = -1;
                        kv[nh++] = (keyed){half_edge_key(m, g, bits), g};
                    }
                }
            m->adj[h] = -1;
            kv[nh++] = (keyed){half_edge_key(m, h, bits), h};
        }
    }
    qsort(kv, (size_t)nh, sizeof *kv, cmp_keyed);
    uint64_t *key = fs_malloc(((size_t)nh + 1) * sizeof *key);
    int32_t *val = fs_malloc(((size_t)nh + 1) * sizeof *val);
    for (int32_t i = 0; i < nh; i++) {
        key[i] = kv[i].key;
        val[i] = kv[i].val;
    }
    int rc = pair_sorted(m, key, val, nh, mesh_shifted(m));
    free(key);
    free(val);
    free(kv);
    free(tris);
    free(dirty);
    return rc;
}

bool fs_mesh_check(const fs_mesh *m, char *why, size_t len)
{
    char dummy[8];
    if (!why) {
        why = dummy;
        len = sizeof dummy;
    }
    int32_t nh = 3 * m->n_tris;
    for (int32_t t = 0; t < m->n_tris; t++) {
        const int32_t *v = m->tri + 3 * (size_t)t;
        for (int k = 0; k < 3; k++)
            if (v[k] < 0 || v[k] >= m->n_nodes) {
                snprintf(why, len, "triangle %d: corner %d is node %d, not one of the %d nodes", (int)t, k, (int)v[k],
                         (int)m->n_nodes);
                return false;
            }
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
            snprintf(why, len, "triangle %d has node %d twice", (int)t, (int)(v[0] == v[1] || v[0] == v[2] ? v[0] : v[1]));
            return false;
        }
        double area = fs_mesh_tri_area(m, t);
        if (!(area > 0.0)) {
            snprintf(why, len, "triangle %d (nodes %d %d %d) has signed area %g: inverted or degenerate", (int)t,
                     (int)v[0], (int)v[1], (int)v[2], area);
            return false;
        }
    }
    if (!m->adj) {
        snprintf(why, len, "the mesh has no adjacency");
        return false;
    }
    int32_t *start, *list;
    node_half_edges(m, &start, &list);
    bool ok = true;
    for (int32_t h = 0; h < nh && ok; h++) {
        half_edge e = half_edge_of(m, h);
        int32_t u = m->adj[h];
        if (u >= m->n_tris || (u >= 0 && partner(m, h) < 0)) {
            snprintf(why, len, "triangle %d, edge %d (nodes %d-%d): its neighbour %d does not share it back", (int)(h / 3),
                     (int)(h % 3), (int)e.from, (int)e.to, (int)u);
            ok = false;
        }
        for (int32_t p = start[e.from]; p < start[e.from + 1] && ok; p++)
            if (list[p] != h && same_direction(half_edge_of(m, list[p]), e)) {
                snprintf(why, len, "edge %d-%d runs the same way in triangles %d and %d: not a manifold, or not "
                         "consistently oriented", (int)e.from, (int)e.to, (int)(h / 3), (int)(list[p] / 3));
                ok = false;
            }
        for (int32_t p = start[e.to]; p < start[e.to + 1] && ok && u < 0; p++)
            if (opposite(half_edge_of(m, list[p]), e)) {
                snprintf(why, len, "edge %d-%d of triangles %d and %d is not joined in adj", (int)e.from, (int)e.to,
                         (int)(h / 3), (int)(list[p] / 3));
                ok = false;
            }
    }
    /* one fan per node: corners of a node joined across their shared edges at it (a half-edge from
     * the node joins the corner at its start with the neighbour's corner there; its partner starts at
     * the other end, so each shared edge at the node is seen from the triangle where it leaves it) */
    int32_t *parent = NULL;
    if (ok) {
        parent = fs_malloc(((size_t)nh + 1) * sizeof *parent);
        fs_uf_init(parent, nh);
        for (int32_t h = 0; h < nh; h++) {
            int32_t g = partner(m, h);
            if (g >= 0) /* g runs from h's end to h's start: its end corner (g's next) is h's corner */
                fs_uf_union(parent, h, 3 * (g / 3) + (g % 3 + 1) % 3);
        }
        for (int32_t i = 0; i < m->n_nodes && ok; i++) {
            int32_t fans = 0;
            for (int32_t p = start[i]; p < start[i + 1]; p++)
                fans += fs_uf_find(parent, list[p]) == list[p];
            if (fans > 1) {
                snprintf(why, len, "node %d: its %d triangles form %d fans (a pinched node, not a manifold)", (int)i,
                         (int)(start[i + 1] - start[i]), (int)fans);
                ok = false;
            }
        }
    }
    free(parent);
    free(start);
    free(list);
    return ok;
}

void fs_mesh_drop_derived(fs_mesh *m)
{
    free(m->edge);
    free(m->edge_tri);
    free(m->tri_edge);
    free(m->ring_start);
    free(m->ring_tri);
    m->edge = m->edge_tri = m->tri_edge = m->ring_start = m->ring_tri = NULL;
    m->n_edges = 0;
}

/* Partners of part p of the half-edges (fs_mesh_build_edges' first pass). */
typedef struct {
    const fs_mesh *m;
    int parts;
    int32_t *partner;
} partner_pass;

static void partners_of_part(void *ctx, int32_t p)
{
    partner_pass *pp = ctx;
    int32_t h0, h1;
    fs_parallel_part(3 * pp->m->n_tris, pp->parts, p, &h0, &h1);
    for (int32_t h = h0; h < h1; h++)
        pp->partner[h] = partner(pp->m, h);
}

/* design: edges are numbered in the order of their first half-edge. The partners, the costly part,
 * are found first, in parallel for a large mesh (each half-edge's on its own); the numbering is one
 * pass in half-edge order, as before, so it does not depend on the thread count. */
void fs_mesh_build_edges(fs_mesh *m)
{
    int32_t nh = 3 * m->n_tris;
    free(m->edge);
    free(m->edge_tri);
    free(m->tri_edge);
    partner_pass pp = {m, mesh_parts(nh, m->n_nodes), fs_malloc((size_t)(nh ? nh : 1) * sizeof(int32_t))};
    fs_parallel_for(pp.parts, pp.parts, partners_of_part, &pp);
    m->tri_edge = fs_malloc((size_t)(nh ? nh : 1) * sizeof *m->tri_edge);
    for (int32_t h = 0; h < nh; h++)
        m->tri_edge[h] = -1;
    /* room for the edges of a closed mesh (half as many as half-edges) and some boundary: memory
     * of that size is often at hand, freed by the passes before, where the worst case (an edge per
     * half-edge) would be mapped and faulted in afresh */
    int32_t cap = nh / 2 + nh / 16 + 16, ne = 0;
    int32_t *edge = fs_malloc((size_t)cap * 2 * sizeof *edge);
    int32_t *edge_tri = fs_malloc((size_t)cap * 2 * sizeof *edge_tri);
    for (int32_t h = 0; h < nh; h++) {
        if (m->tri_edge[h] >= 0)
            continue;
        if (FS_ARRAY_GROW(cap, ne + 1, 16)) {
            FS_ARRAY_RESIZE(edge, 2 * (size_t)cap);
            FS_ARRAY_RESIZE(edge_tri, 2 * (size_t)cap);
        }
        int32_t a = m->tri[h], b = m->tri[3 * (h / 3) + (h % 3 + 1) % 3];
        edge[2 * ne] = a < b ? a : b;
        edge[2 * ne + 1] = a < b ? b : a;
        edge_tri[2 * ne] = h / 3;
        edge_tri[2 * ne + 1] = m->adj[h];
        m->tri_edge[h] = ne;
        int32_t g = pp.partner[h];
        if (g >= 0)
            m->tri_edge[g] = ne;
        ne++;
    }
    free(pp.partner);
    m->n_edges = ne;
    m->edge = fs_realloc(edge, (size_t)(ne ? ne : 1) * 2 * sizeof *edge);
    m->edge_tri = fs_realloc(edge_tri, (size_t)(ne ? ne : 1) * 2 * sizeof *edge_tri);
}

/* Corners k = 3 t + c are walked around their node: the next corner counter-clockwise lies across
 * edge (c + 2) % 3 (-1 at a boundary). The edge clockwise of corner k is half-edge k itself. */
static int32_t corner_ccw(const fs_mesh *m, int32_t k)
{
    return partner(m, 3 * (k / 3) + (k % 3 + 2) % 3);
}

/* Orders the corners of one node counter-clockwise, fan by fan: first the fans that start at a
 * boundary edge, then closed fans from their lowest corner. fan_flags marks the first corner of each
 * fan (1) and whether that fan is open (2). visited has one byte per corner of the mesh. */
static void walk_node(const fs_mesh *m, const int32_t *corners, int32_t deg, uint8_t *visited, int32_t *out,
                      uint8_t *fan_flags)
{
    int32_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (int32_t i = 0; i < deg && n < deg; i++) {
            int32_t k = corners[i];
            if (visited[k] || (pass == 0 && m->adj[k] >= 0))
                continue;
            int32_t begin = n, s = k;
            do {
                visited[s] = 1;
                fan_flags[n] = 0;
                out[n++] = s;
                s = corner_ccw(m, s);
            } while (s >= 0 && s != k && !visited[s] && n < deg);
            fan_flags[begin] = (uint8_t)(1 | (pass == 0 ? 2 : 0));
        }
    }
}

/* The shared state of fs_mesh_build_rings' parallel pass. */
typedef struct {
    fs_mesh *m;
    int parts;
    const int32_t *start, *corner;
    uint8_t *visited;
    int32_t maxdeg;
} ring_pass;

/* The rings of part p of the nodes (a node's corners are its own: no two parts touch one). */
static void rings_of_part(void *ctx, int32_t p)
{
    ring_pass *rp = ctx;
    fs_mesh *m = rp->m;
    int32_t v0, v1;
    fs_parallel_part(m->n_nodes, rp->parts, p, &v0, &v1);
    int32_t *order = fs_malloc((size_t)(rp->maxdeg ? rp->maxdeg : 1) * sizeof *order);
    uint8_t *flags = fs_malloc((size_t)(rp->maxdeg ? rp->maxdeg : 1));
    for (int32_t v = v0; v < v1; v++) {
        int32_t s = rp->start[v], deg = rp->start[v + 1] - s;
        walk_node(m, rp->corner + s, deg, rp->visited, order, flags);
        m->ring_start[v] = s;
        for (int32_t i = 0; i < deg; i++)
            m->ring_tri[s + i] = order[i] / 3;
    }
    free(order);
    free(flags);
}

void fs_mesh_build_rings(fs_mesh *m)
{
    int32_t *start, *corner;
    node_half_edges(m, &start, &corner);
    int32_t nh = 3 * m->n_tris;
    ring_pass rp = {m, mesh_parts(nh, m->n_nodes), start, corner, fs_calloc((size_t)(nh ? nh : 1), 1), 0};
    for (int32_t v = 0; v < m->n_nodes; v++)
        if (start[v + 1] - start[v] > rp.maxdeg)
            rp.maxdeg = start[v + 1] - start[v];
    free(m->ring_start);
    free(m->ring_tri);
    m->ring_start = fs_malloc(((size_t)m->n_nodes + 1) * sizeof *m->ring_start);
    m->ring_tri = fs_malloc((size_t)(nh ? nh : 1) * sizeof *m->ring_tri);
    fs_parallel_for(rp.parts, rp.parts, rings_of_part, &rp);
    m->ring_start[m->n_nodes] = nh;
    free(rp.visited);
    free(start);
    free(corner);
}

/* ---- Voronoi dual ---- */

/* Circumcentre of the planar triangle (a, b, c); false if it is degenerate. */
static bool circumcenter2(const double *a, const double *b, const double *c, double *out)
{
    double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
    double d = 2.0 * (bx * cy - by * cx);
    if (d == 0.0) {
        out[0] = (a[0] + b[0] + c[0]) / 3.0;
        out[1] = (a[1] + b[1] + c[1]) / 3.0;
        out[2] = 0.0;
        return false;
    }
    double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    out[0] = a[0] + (cy * b2 - by * c2) / d;
    out[1] = a[1] + (bx * c2 - cx * b2) / d;
    out[2] = 0.0;
    return true;
}

/* Circumcentre of the 3-D triangle (a, b, c) projected radially onto the sphere of radius r. */
static void circumcenter_sphere(const double *a, const double *b, const double *c, double r, double *out)
{
    double ab[3], ac[3], n[3], u[3], w[3], p[3];
    fs_sub3(ab, b, a);
    fs_sub3(ac, c, a);
    fs_cross3(n, ab, ac);
    double n2 = fs_dot3(n, n);
    if (n2 == 0.0) {
        for (int k = 0; k < 3; k++)
            p[k] = a[k] + b[k] + c[k];
    } else {
        fs_cross3(u, n, ab);
        fs_cross3(w, ac, n);
        double ac2 = fs_dot3(ac, ac), ab2 = fs_dot3(ab, ab);
        for (int k = 0; k < 3; k++)
            p[k] = a[k] + (ac2 * u[k] + ab2 * w[k]) / (2.0 * n2);
        /* a circumcentre at the origin (a great-circle triangle) has no projection: use the normal */
        if (fs_dot3(p, p) <= 1e-24 * ab2)
            for (int k = 0; k < 3; k++)
                p[k] = n[k];
    }
    double len = fs_norm3(p);
    for (int k = 0; k < 3; k++)
        out[k] = len > 0.0 ? p[k] * r / len : 0.0;
}

/* Signed area of the spherical triangle (a, b, c) on the unit sphere (Van Oosterom and Strackee). */
static double spherical_triangle_area(const double *a, const double *b, const double *c)
{
    double bc[3];
    fs_cross3(bc, b, c);
    double triple = fs_dot3(a, bc);
    double denom = 1.0 + fs_dot3(a, b) + fs_dot3(b, c) + fs_dot3(c, a);
    return 2.0 * atan2(triple, denom);
}

/* The clipping box: the domain rectangle in the directions that do not wrap. */
typedef struct {
    bool clip[2];
    double lo[2], hi[2];
} clip_box;

static clip_box make_box(const fs_mesh *m)
{
    clip_box b = {{false, false}, {0.0, 0.0}, {0.0, 0.0}};
    if (m->domain.type == FS_DOMAIN_SPHERE)
        return b;
    b.clip[0] = period_x(m) == 0.0;
    b.clip[1] = period_y(m) == 0.0;
    b.hi[0] = fs_domain_extent_x(&m->domain);
    b.hi[1] = fs_domain_extent_y(&m->domain);
    return b;
}

/* Liang-Barsky: the parameter range [t0, t1] of p + t d inside the box (only the clipped
 * directions). Returns false when the range is empty. */
static bool clip_line(const clip_box *b, const double *p, const double *d, double *t0, double *t1)
{
    for (int k = 0; k < 2; k++) {
        if (!b->clip[k])
            continue;
        if (d[k] == 0.0) {
            if (p[k] < b->lo[k] || p[k] > b->hi[k])
                return false;
            continue;
        }
        double ta = (b->lo[k] - p[k]) / d[k], tb = (b->hi[k] - p[k]) / d[k];
        if (ta > tb) {
            double s = ta;
            ta = tb;
            tb = s;
        }
        if (ta > *t0)
            *t0 = ta;
        if (tb < *t1)
            *t1 = tb;
    }
    return *t0 < *t1;
}

/* Sutherland-Hodgman clip of polygon (x, y; n vertices) against one side of the box; writes to
 * (ox, oy) and returns the new count (at most 2 n). side: 0/1 = lower/upper bound. */
static int clip_polygon_side(const double *x, const double *y, int n, int axis, int side, double bound, double *ox,
                             double *oy)
{
    int count = 0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        double pi = axis ? y[i] : x[i], pj = axis ? y[j] : x[j];
        bool in_i = side ? pi <= bound : pi >= bound;
        bool in_j = side ? pj <= bound : pj >= bound;
        if (in_i) {
            ox[count] = x[i];
            oy[count] = y[i];
            count++;
        }
        if (in_i != in_j) {
            double s = (bound - pi) / (pj - pi);
            ox[count] = x[i] + s * (x[j] - x[i]);
            oy[count] = y[i] + s * (y[j] - y[i]);
            if (axis)
                oy[count] = bound;
            else
                ox[count] = bound;
            count++;
        }
    }
    return count;
}

static double polygon_area(const double *x, const double *y, int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        s += x[i] * y[j] - x[j] * y[i];
    }
    return 0.5 * s;
}

/* Scratch for the cells of the plane and cylinder. */
typedef struct {
    double *x, *y, *tx, *ty;
    int cap;
} poly_buf;

static void poly_reserve(poly_buf *p, int n)
{
    if (FS_ARRAY_GROW(p->cap, n, 64)) {
        FS_ARRAY_RESIZE(p->x, p->cap);
        FS_ARRAY_RESIZE(p->y, p->cap);
        FS_ARRAY_RESIZE(p->tx, p->cap);
        FS_ARRAY_RESIZE(p->ty, p->cap);
    }
}

/* Area of a polygon (relative coordinates, CCW) clipped to the box shifted by -origin. */
static double clipped_area(poly_buf *p, int n, const clip_box *box, const double *origin)
{
    poly_reserve(p, 16 * n + 16);
    double *x = p->x, *y = p->y, *tx = p->tx, *ty = p->ty;
    for (int axis = 0; axis < 2 && n > 0; axis++) {
        if (!box->clip[axis])
            continue;
        for (int side = 0; side < 2 && n > 0; side++) {
            double bound = (side ? box->hi[axis] : box->lo[axis]) - origin[axis];
            n = clip_polygon_side(x, y, n, axis, side, bound, tx, ty);
            double *s = x;
            x = tx;
            tx = s;
            s = y;
            y = ty;
            ty = s;
        }
    }
    double a = n >= 3 ? polygon_area(x, y, n) : 0.0;
    p->x = x;
    p->y = y;
    p->tx = tx;
    p->ty = ty;
    return a;
}

void fs_mesh_boundary_normal(const fs_mesh *m, int32_t t, int i, double *n)
{
    double a[3], b[3];
    fs_mesh_corner(m, t, i, a);
    fs_mesh_corner(m, t, (i + 1) % 3, b);
    double dx = b[0] - a[0], dy = b[1] - a[1], len = hypot(dx, dy);
    n[0] = len > 0.0 ? dy / len : 0.0;
    n[1] = len > 0.0 ? -dx / len : 0.0;
}

/* The corners of node v in the order of its ring, with fan flags as walk_node gives them; false
 * when a ring triangle holds v twice (tiny periodic meshes), which needs walk_node. */
static bool ring_corners(const fs_mesh *m, int32_t v, int32_t *out, uint8_t *flags)
{
    int32_t s0 = m->ring_start[v], deg = m->ring_start[v + 1] - s0;
    for (int32_t k = 0; k < deg; k++) {
        int32_t t = m->ring_tri[s0 + k], found = 0;
        for (int c = 0; c < 3; c++)
            if (m->tri[3 * t + c] == v) {
                out[k] = 3 * t + c;
                found++;
            }
        if (found != 1)
            return false;
    }
    for (int32_t k = 0; k < deg; k++) {
        int32_t prev = k > 0 ? out[k - 1] : -1;
        bool joined = prev >= 0 && m->adj[3 * (prev / 3) + (prev % 3 + 2) % 3] == out[k] / 3;
        flags[k] = joined ? 0 : (uint8_t)(1 | (m->adj[out[k]] < 0 ? 2 : 0));
    }
    return true;
}

/* design: a node's Voronoi cell is the polygon of the circumcentres of its ring, in order (thesis
 * §5.2). On the plane and cylinder the circumcentres are brought into the node's frame with the
 * corner shifts; an open fan (a boundary node) is closed by two rays along the outward normals of
 * its boundary edges, reaching far beyond the domain, and a third far point on their bisector, then
 * the polygon is clipped to the domain rectangle in the directions that do not wrap (not to the
 * convex hull), so the cells of points inside the rectangle partition it exactly. On the sphere the
 * cell is the spherical polygon of the projected circumcentres, summed as signed spherical
 * triangles from the node: the cells tile the sphere, so the areas sum to 4 pi R^2 to rounding.
 * Dual edges: the segment between the two circumcentres (sphere: the great-circle arc), clipped like
 * the cells; a boundary edge has the ray from its triangle's circumcentre along the outward normal,
 * clipped to the rectangle. */
int fs_voronoi_build(const fs_mesh *m, fs_voronoi *out)
{
    memset(out, 0, sizeof *out);
    if (!m->ring_start || !m->tri_edge) {
        fs_error(FS_ERR_INTERNAL, "voronoi: the mesh has no edges or rings (build them first)");
        return -1;
    }
    bool sphere = m->domain.type == FS_DOMAIN_SPHERE;
    double r = m->domain.radius;
    double px = period_x(m), py = period_y(m);
    int32_t nt = m->n_tris;
    out->circumcenter = fs_malloc((size_t)(nt ? nt : 1) * 3 * sizeof *out->circumcenter);
    out->cell_area = fs_calloc((size_t)(m->n_nodes ? m->n_nodes : 1), sizeof *out->cell_area);
    out->edge_length = fs_calloc((size_t)(m->n_edges ? m->n_edges : 1), sizeof *out->edge_length);

    for (int32_t t = 0; t < nt; t++) {
        double a[3], b[3], c[3];
        fs_mesh_corner(m, t, 0, a);
        fs_mesh_corner(m, t, 1, b);
        fs_mesh_corner(m, t, 2, c);
        if (sphere)
            circumcenter_sphere(a, b, c, r, out->circumcenter + 3 * (size_t)t);
        else
            circumcenter2(a, b, c, out->circumcenter + 3 * (size_t)t);
    }

    clip_box box = make_box(m);
    double diag = sphere ? 0.0 : hypot(fs_domain_extent_x(&m->domain), fs_domain_extent_y(&m->domain));

    int32_t *start = NULL, *corner = NULL;
    uint8_t *visited = NULL;
    int32_t maxdeg = 0;
    for (int32_t v = 0; v < m->n_nodes; v++)
        if (m->ring_start[v + 1] - m->ring_start[v] > maxdeg)
            maxdeg = m->ring_start[v + 1] - m->ring_start[v];
    int32_t *order = fs_malloc((size_t)(maxdeg ? maxdeg : 1) * sizeof *order);
    uint8_t *flags = fs_malloc((size_t)(maxdeg ? maxdeg : 1));
    poly_buf poly = {NULL, NULL, NULL, NULL, 0};

    for (int32_t v = 0; v < m->n_nodes; v++) {
        int32_t deg = m->ring_start[v + 1] - m->ring_start[v];
        if (!ring_corners(m, v, order, flags)) {
            if (!start) {
                node_half_edges(m, &start, &corner);
                visited = fs_calloc((size_t)3 * (size_t)nt + 1, 1);
            }
            walk_node(m, corner + start[v], deg, visited, order, flags);
        }
        const double *pv = m->pos + 3 * (size_t)v;
        double area = 0.0;
        for (int32_t f = 0; f < deg;) {
            int32_t e = f + 1;
            while (e < deg && !(flags[e] & 1))
                e++;
            bool open = (flags[f] & 2) != 0;
            if (sphere) {
                double vu[3], cu[3], cn[3];
                for (int k = 0; k < 3; k++)
                    vu[k] = pv[k] / r;
                int32_t last = open ? e - 1 : e;
                for (int32_t i = f; i < last; i++) {
                    int32_t ki = order[i], kj = order[i + 1 < e ? i + 1 : f];
                    for (int k = 0; k < 3; k++) {
                        cu[k] = out->circumcenter[3 * (ki / 3) + k] / r;
                        cn[k] = out->circumcenter[3 * (kj / 3) + k] / r;
                    }
                    area += r * r * spherical_triangle_area(vu, cu, cn);
                }
            } else {
                int cnt = (int)(e - f);
                poly_reserve(&poly, 16 * (cnt + 3) + 16);
                double far = 0.0;
                for (int32_t i = f; i < e; i++) {
                    int32_t k = order[i];
                    int32_t t = (int32_t)(k / 3);
                    int c = (int)(k % 3);
                    static const int8_t no_shift[2] = {0, 0};
                    const int8_t *s = m->shift ? m->shift + 6 * (size_t)t + 2 * c : no_shift;
                    const double *cc = out->circumcenter + 3 * (size_t)t;
                    double x = cc[0] - s[0] * px - pv[0], y = cc[1] - s[1] * py - pv[1];
                    poly.x[i - f] = x;
                    poly.y[i - f] = y;
                    double d = hypot(x, y);
                    if (d > far)
                        far = d;
                }
                if (open) {
                    /* rays dual to the two boundary edges, closed far outside the domain */
                    double n_first[2], n_last[2];
                    int32_t tf = (int32_t)(order[f] / 3), tl = (int32_t)(order[e - 1] / 3);
                    fs_mesh_boundary_normal(m, tf, (int)(order[f] % 3), n_first);
                    fs_mesh_boundary_normal(m, tl, (int)((order[e - 1] % 3 + 2) % 3), n_last);
                    double reach = 4.0 * (diag + far) + 1.0;
                    double ang = atan2(n_last[0] * n_first[1] - n_last[1] * n_first[0],
                                       n_last[0] * n_first[0] + n_last[1] * n_first[1]);
                    double cs = cos(0.5 * ang), sn = sin(0.5 * ang);
                    double bis[2] = {cs * n_last[0] - sn * n_last[1], sn * n_last[0] + cs * n_last[1]};
                    double xl = poly.x[cnt - 1], yl = poly.y[cnt - 1], xf = poly.x[0], yf = poly.y[0];
                    poly.x[cnt] = xl + reach * n_last[0];
                    poly.y[cnt] = yl + reach * n_last[1];
                    poly.x[cnt + 1] = 2.0 * reach * bis[0];
                    poly.y[cnt + 1] = 2.0 * reach * bis[1];
                    poly.x[cnt + 2] = xf + reach * n_first[0];
                    poly.y[cnt + 2] = yf + reach * n_first[1];
                    cnt += 3;
                }
                bool inside = true;
                for (int i = 0; i < cnt && inside; i++)
                    for (int k = 0; k < 2; k++) {
                        double q = (k ? poly.y[i] : poly.x[i]) + pv[k];
                        inside &= !box.clip[k] || (q >= box.lo[k] && q <= box.hi[k]);
                    }
                area += inside ? polygon_area(poly.x, poly.y, cnt) : clipped_area(&poly, cnt, &box, pv);
            }
            f = e;
        }
        out->cell_area[v] = area;
    }
    free(poly.x);
    free(poly.y);
    free(poly.tx);
    free(poly.ty);
    free(order);
    free(flags);
    free(visited);
    free(start);
    free(corner);

    for (int32_t e = 0; e < m->n_edges; e++) {
        int32_t t = m->edge_tri[2 * e], u = m->edge_tri[2 * e + 1];
        int i = 0;
        while (i < 2 && m->tri_edge[3 * t + i] != e)
            i++;
        int32_t h = 3 * t + i;
        const double *ct = out->circumcenter + 3 * (size_t)t;
        double len = 0.0;
        if (sphere) {
            double q[3], cr[3];
            if (u >= 0) {
                memcpy(q, out->circumcenter + 3 * (size_t)u, sizeof q);
            } else {
                double a[3], b[3];
                fs_mesh_corner(m, t, i, a);
                fs_mesh_corner(m, t, (i + 1) % 3, b);
                for (int k = 0; k < 3; k++)
                    q[k] = 0.5 * (a[k] + b[k]);
            }
            fs_cross3(cr, ct, q);
            len = r * atan2(fs_norm3(cr), fs_dot3(ct, q));
        } else if (u >= 0) {
            /* bring u's circumcentre into t's frame through the shared corner */
            double off[2] = {0.0, 0.0};
            if (m->shift && (px > 0.0 || py > 0.0)) {
                int32_t g = partner(m, h);
                const int8_t *st = m->shift + 6 * (size_t)t + 2 * i;
                const int8_t *su = m->shift + 6 * (size_t)u + 2 * ((g % 3 + 1) % 3);
                off[0] = (st[0] - su[0]) * px;
                off[1] = (st[1] - su[1]) * py;
            }
            const double *cu = out->circumcenter + 3 * (size_t)u;
            double p0[2] = {ct[0], ct[1]};
            double d[2] = {cu[0] + off[0] - ct[0], cu[1] + off[1] - ct[1]};
            double t0 = 0.0, t1 = 1.0;
            if (clip_line(&box, p0, d, &t0, &t1))
                len = (t1 - t0) * hypot(d[0], d[1]);
        } else {
            double n[2], p0[2] = {ct[0], ct[1]};
            fs_mesh_boundary_normal(m, t, i, n);
            double t0 = 0.0, t1 = INFINITY;
            if (clip_line(&box, p0, n, &t0, &t1)) {
                if (isfinite(t1)) {
                    len = t1 - t0;
                } else {
                    double a[3], b[3];
                    fs_mesh_corner(m, t, i, a);
                    fs_mesh_corner(m, t, (i + 1) % 3, b);
                    len = hypot(0.5 * (a[0] + b[0]) - ct[0], 0.5 * (a[1] + b[1]) - ct[1]);
                }
            }
        }
        out->edge_length[e] = len;
    }
    return 0;
}

void fs_voronoi_free(fs_voronoi *v)
{
    free(v->circumcenter);
    free(v->cell_area);
    free(v->edge_length);
    memset(v, 0, sizeof *v);
}
