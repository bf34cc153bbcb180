/* Tetrahedral meshes of a layer: geometry, node lists, face matching, checks, and the layered Delaunay mesher. */
#include "geom/tetmesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/vec.h"
#include "geom/delaunay.h"

const int fs_tet_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* ---- geometry ---- */

double fs_tet_volume(const double x[12])
{
    double a[3], b[3], c[3], cr[3];
    fs_sub3(a, x + 3, x);
    fs_sub3(b, x + 6, x);
    fs_sub3(c, x + 9, x);
    fs_cross3(cr, a, b);
    return fs_dot3(cr, c) / 6.0;
}

double fs_tet_quality(const double x[12])
{
    double sum = 0.0;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) {
            double d[3];
            fs_sub3(d, x + 3 * j, x + 3 * i);
            sum += fs_dot3(d, d);
        }
    double rms = sqrt(sum / 6.0);
    if (!(rms > 0.0))
        return 0.0;
    return 6.0 * sqrt(2.0) * fs_tet_volume(x) / (rms * rms * rms);
}

void fs_tetmesh_corner(const fs_tetmesh *m, int32_t t, int c, double out[3])
{
    int32_t v = m->tet[4 * (size_t)t + c];
    const int8_t *s = m->shift + 8 * (size_t)t + 2 * c;
    const double *p = m->pos + 3 * (size_t)v;
    out[0] = p[0] + s[0] * m->period[0];
    out[1] = p[1] + s[1] * m->period[1];
    out[2] = p[2];
}

void fs_tetmesh_corners(const fs_tetmesh *m, int32_t t, double x[12])
{
    for (int c = 0; c < 4; c++)
        fs_tetmesh_corner(m, t, c, x + 3 * c);
}

double fs_tetmesh_volume(const fs_tetmesh *m, int32_t t)
{
    double x[12];
    fs_tetmesh_corners(m, t, x);
    return fs_tet_volume(x);
}

/* ---- storage ---- */

void fs_tet_list_push(fs_tet_list *l, int32_t v)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 8;
        l->v = fs_realloc(l->v, (size_t)l->cap * sizeof *l->v);
    }
    l->v[l->n++] = v;
}

void fs_tet_list_free(fs_tet_list *l)
{
    free(l->v);
    memset(l, 0, sizeof *l);
}

static void list_remove(fs_tet_list *l, int32_t v)
{
    for (int32_t k = 0; k < l->n; k++)
        if (l->v[k] == v) {
            memmove(l->v + k, l->v + k + 1, (size_t)(l->n - k - 1) * sizeof *l->v);
            l->n--;
            return;
        }
}

static void list_insert_sorted(fs_tet_list *l, int32_t v)
{
    fs_tet_list_push(l, v);
    int32_t k = l->n - 1;
    while (k > 0 && l->v[k - 1] > v) {
        l->v[k] = l->v[k - 1];
        k--;
    }
    l->v[k] = v;
}

void fs_tetmesh_free(fs_tetmesh *m)
{
    free(m->pos);
    free(m->zeta);
    free(m->tet);
    free(m->shift);
    if (m->node_tets)
        for (int32_t i = 0; i < m->n_nodes; i++)
            fs_tet_list_free(&m->node_tets[i]);
    free(m->node_tets);
    memset(m, 0, sizeof *m);
}

int32_t fs_tetmesh_add_node(fs_tetmesh *m, const double pos[3], double zeta)
{
    if (m->n_nodes == m->cap_nodes) {
        int32_t cap = m->cap_nodes ? m->cap_nodes + m->cap_nodes / 2 + 16 : 64;
        m->pos = fs_realloc(m->pos, 3 * (size_t)cap * sizeof *m->pos);
        m->zeta = fs_realloc(m->zeta, (size_t)cap * sizeof *m->zeta);
        if (m->node_tets) {
            m->node_tets = fs_realloc(m->node_tets, (size_t)cap * sizeof *m->node_tets);
            memset(m->node_tets + m->cap_nodes, 0, (size_t)(cap - m->cap_nodes) * sizeof *m->node_tets);
        }
        m->cap_nodes = cap;
    }
    int32_t i = m->n_nodes++;
    memcpy(m->pos + 3 * (size_t)i, pos, 3 * sizeof *pos);
    m->zeta[i] = zeta;
    return i;
}

int32_t fs_tetmesh_add_tet(fs_tetmesh *m, const int32_t v[4], const int8_t *shift)
{
    if (m->n_tets == m->cap_tets) {
        int32_t cap = m->cap_tets ? m->cap_tets + m->cap_tets / 2 + 16 : 64;
        m->tet = fs_realloc(m->tet, 4 * (size_t)cap * sizeof *m->tet);
        m->shift = fs_realloc(m->shift, 8 * (size_t)cap * sizeof *m->shift);
        m->cap_tets = cap;
    }
    int32_t t = m->n_tets++;
    memcpy(m->tet + 4 * (size_t)t, v, 4 * sizeof *v);
    if (shift)
        memcpy(m->shift + 8 * (size_t)t, shift, 8);
    else
        memset(m->shift + 8 * (size_t)t, 0, 8);
    if (m->node_tets)
        for (int c = 0; c < 4; c++)
            list_insert_sorted(&m->node_tets[v[c]], t);
    return t;
}

void fs_tetmesh_set_tet(fs_tetmesh *m, int32_t t, const int32_t v[4], const int8_t *shift)
{
    int32_t *old = m->tet + 4 * (size_t)t;
    if (m->node_tets) {
        for (int c = 0; c < 4; c++) {
            bool kept = false;
            for (int d = 0; d < 4; d++)
                kept = kept || v[d] == old[c];
            if (!kept)
                list_remove(&m->node_tets[old[c]], t);
        }
        for (int c = 0; c < 4; c++) {
            bool had = false;
            for (int d = 0; d < 4; d++)
                had = had || old[d] == v[c];
            if (!had)
                list_insert_sorted(&m->node_tets[v[c]], t);
        }
    }
    memcpy(old, v, 4 * sizeof *v);
    if (shift)
        memcpy(m->shift + 8 * (size_t)t, shift, 8);
    else
        memset(m->shift + 8 * (size_t)t, 0, 8);
}

void fs_tetmesh_build_node_tets(fs_tetmesh *m)
{
    if (m->node_tets)
        for (int32_t i = 0; i < m->n_nodes; i++)
            fs_tet_list_free(&m->node_tets[i]);
    free(m->node_tets);
    m->node_tets = fs_calloc((size_t)(m->cap_nodes ? m->cap_nodes : 1), sizeof *m->node_tets);
    for (int32_t t = 0; t < m->n_tets; t++)
        for (int c = 0; c < 4; c++) {
            fs_tet_list *l = &m->node_tets[m->tet[4 * (size_t)t + c]];
            if (l->n == 0 || l->v[l->n - 1] != t)
                fs_tet_list_push(l, t);
        }
}

int32_t fs_tetmesh_edge_tets(const fs_tetmesh *m, int32_t a, int32_t b, const int8_t *rel, fs_tet_list *out)
{
    FS_ASSERT(m->node_tets);
    out->n = 0;
    const fs_tet_list *la = &m->node_tets[a];
    for (int32_t k = 0; k < la->n; k++) {
        int32_t t = la->v[k];
        const int32_t *v = m->tet + 4 * (size_t)t;
        const int8_t *s = m->shift + 8 * (size_t)t;
        int ca = -1, cb = -1;
        for (int c = 0; c < 4; c++) {
            if (v[c] == a)
                ca = c;
            if (v[c] == b)
                cb = c;
        }
        if (ca < 0 || cb < 0)
            continue;
        if (rel && (s[2 * cb] - s[2 * ca] != rel[0] || s[2 * cb + 1] - s[2 * ca + 1] != rel[1]))
            continue;
        fs_tet_list_push(out, t);
    }
    return out->n;
}

/* ---- faces and edges: keys of corners (node, shift) ---- */

/* A face or an edge as its k corners sorted by (node, shift), shifts relative to the first. */
typedef struct {
    int32_t node[3];
    int8_t shift[6];
    int k;
    int parity; /* 1 when the sort was an odd permutation of the given order */
} corner_key;

static bool key_corner_less(const corner_key *q, int i, int j)
{
    if (q->node[i] != q->node[j])
        return q->node[i] < q->node[j];
    if (q->shift[2 * i] != q->shift[2 * j])
        return q->shift[2 * i] < q->shift[2 * j];
    return q->shift[2 * i + 1] < q->shift[2 * j + 1];
}

static void key_swap(corner_key *q, int i, int j)
{
    int32_t n = q->node[i];
    q->node[i] = q->node[j];
    q->node[j] = n;
    for (int d = 0; d < 2; d++) {
        int8_t s = q->shift[2 * i + d];
        q->shift[2 * i + d] = q->shift[2 * j + d];
        q->shift[2 * j + d] = s;
    }
    q->parity ^= 1;
}

/* The key of corners cs[0..k-1] of tetrahedron t. */
static corner_key make_key(const fs_tetmesh *m, int32_t t, const int *cs, int k)
{
    corner_key q;
    memset(&q, 0, sizeof q);
    q.k = k;
    for (int i = 0; i < k; i++) {
        q.node[i] = m->tet[4 * (size_t)t + cs[i]];
        q.shift[2 * i] = m->shift[8 * (size_t)t + 2 * cs[i]];
        q.shift[2 * i + 1] = m->shift[8 * (size_t)t + 2 * cs[i] + 1];
    }
    for (int i = 1; i < k; i++)
        for (int j = i; j > 0 && key_corner_less(&q, j, j - 1); j--)
            key_swap(&q, j, j - 1);
    for (int i = k - 1; i >= 0; i--)
        for (int d = 0; d < 2; d++)
            q.shift[2 * i + d] = (int8_t)(q.shift[2 * i + d] - q.shift[d]);
    return q;
}

static bool key_equal(const corner_key *a, const corner_key *b)
{
    return a->k == b->k && !memcmp(a->node, b->node, (size_t)a->k * sizeof a->node[0]) &&
           !memcmp(a->shift, b->shift, 2 * (size_t)a->k);
}

static uint64_t key_hash(const corner_key *q)
{
    uint64_t h = (uint64_t)q->k;
    for (int i = 0; i < q->k; i++) {
        h += (uint64_t)(uint32_t)q->node[i] + ((uint64_t)(uint8_t)q->shift[2 * i] << 32) +
             ((uint64_t)(uint8_t)q->shift[2 * i + 1] << 40) + UINT64_C(0x9e3779b97f4a7c15);
        h = (h ^ (h >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
        h = (h ^ (h >> 27)) * UINT64_C(0x94d049bb133111eb);
        h ^= h >> 31;
    }
    return h;
}

/* Open-addressing table of keys, each stored as its hash and the id (tetrahedron * 8 + which) it
 * came from. */
typedef struct {
    size_t size;
    int64_t *slot;
    uint64_t *hash;
} key_table;

static void table_init(key_table *tab, size_t entries)
{
    tab->size = 16;
    while (tab->size < 2 * entries)
        tab->size *= 2;
    tab->slot = fs_malloc(tab->size * sizeof *tab->slot);
    tab->hash = fs_malloc(tab->size * sizeof *tab->hash);
    for (size_t s = 0; s < tab->size; s++)
        tab->slot[s] = -1;
}

static void table_free(key_table *tab)
{
    free(tab->slot);
    free(tab->hash);
}

/* The slot holding q (whose hash is h), or the empty slot where it would go (then store h there
 * with the id). keyof rebuilds a stored key. */
static size_t table_find(const key_table *tab, const corner_key *q, uint64_t h, const fs_tetmesh *m,
                         corner_key (*keyof)(const fs_tetmesh *, int64_t))
{
    size_t s = (size_t)h & (tab->size - 1);
    while (tab->slot[s] >= 0) {
        if (tab->hash[s] == h) {
            corner_key o = keyof(m, tab->slot[s]);
            if (key_equal(&o, q))
                return s;
        }
        s = (s + 1) & (tab->size - 1);
    }
    return s;
}

static corner_key face_key_of(const fs_tetmesh *m, int64_t id)
{
    return make_key(m, (int32_t)(id / 8), fs_tet_face[id % 8], 3);
}

static const int edge_corners[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

static corner_key edge_key_of(const fs_tetmesh *m, int64_t id)
{
    return make_key(m, (int32_t)(id / 8), edge_corners[id % 8], 2);
}

int32_t fs_tetmesh_adjacency(const fs_tetmesh *m, int32_t *adj)
{
    key_table tab;
    table_init(&tab, 4 * (size_t)m->n_tets);
    int32_t *partner = fs_malloc((4 * (size_t)m->n_tets + 1) * sizeof *partner);
    int32_t bad = 0;
    for (int32_t t = 0; t < m->n_tets; t++)
        for (int f = 0; f < 4; f++) {
            int32_t h = 4 * t + f;
            partner[h] = -1;
            corner_key q = make_key(m, t, fs_tet_face[f], 3);
            uint64_t hq = key_hash(&q);
            size_t s = table_find(&tab, &q, hq, m, face_key_of);
            if (tab.slot[s] < 0) {
                tab.slot[s] = 8 * (int64_t)t + f;
                tab.hash[s] = hq;
                continue;
            }
            int32_t g = (int32_t)(tab.slot[s] / 8) * 4 + (int32_t)(tab.slot[s] % 8);
            corner_key o = face_key_of(m, tab.slot[s]);
            if (partner[g] >= 0 || o.parity == q.parity || g / 4 == t) {
                bad++;
                continue;
            }
            partner[g] = h;
            partner[h] = g;
        }
    for (int32_t h = 0; h < 4 * m->n_tets; h++)
        adj[h] = partner[h] >= 0 ? partner[h] / 4 : -1;
    free(partner);
    table_free(&tab);
    return bad;
}

int32_t fs_tetmesh_components(const fs_tetmesh *m, const int32_t *adj, int32_t *comp)
{
    for (int32_t t = 0; t < m->n_tets; t++)
        comp[t] = -1;
    int32_t *queue = fs_malloc(((size_t)m->n_tets + 1) * sizeof *queue);
    int32_t count = 0;
    for (int32_t t0 = 0; t0 < m->n_tets; t0++) {
        if (comp[t0] >= 0)
            continue;
        int32_t head = 0, tail = 0;
        queue[tail++] = t0;
        comp[t0] = count;
        while (head < tail) {
            int32_t t = queue[head++];
            for (int f = 0; f < 4; f++) {
                int32_t o = adj[4 * (size_t)t + f];
                if (o >= 0 && comp[o] < 0) {
                    comp[o] = count;
                    queue[tail++] = o;
                }
            }
        }
        count++;
    }
    free(queue);
    return count;
}

/* Number of distinct keys among the given corner subsets of every tetrahedron. */
static int64_t count_distinct(const fs_tetmesh *m, int per_tet, const int (*cs)[3], int k,
                              corner_key (*keyof)(const fs_tetmesh *, int64_t))
{
    key_table tab;
    table_init(&tab, (size_t)per_tet * (size_t)m->n_tets);
    int64_t count = 0;
    for (int32_t t = 0; t < m->n_tets; t++)
        for (int w = 0; w < per_tet; w++) {
            corner_key q = make_key(m, t, cs[w], k);
            uint64_t hq = key_hash(&q);
            size_t s = table_find(&tab, &q, hq, m, keyof);
            if (tab.slot[s] < 0) {
                tab.slot[s] = 8 * (int64_t)t + w;
                tab.hash[s] = hq;
                count++;
            }
        }
    table_free(&tab);
    return count;
}

int fs_tetmesh_check(const fs_tetmesh *m, fs_tetmesh_report *r)
{
    memset(r, 0, sizeof *r);
    r->min_volume = INFINITY;
    r->min_quality = INFINITY;
    uint8_t *used = fs_calloc((size_t)m->n_nodes + 1, 1);
    for (int32_t t = 0; t < m->n_tets; t++) {
        double x[12];
        fs_tetmesh_corners(m, t, x);
        double v = fs_tet_volume(x);
        r->volume += v;
        r->min_volume = fmin(r->min_volume, v);
        r->min_quality = fmin(r->min_quality, fs_tet_quality(x));
        r->nonpositive += !(v > 0.0);
        for (int c = 0; c < 4; c++)
            used[m->tet[4 * (size_t)t + c]] = 1;
    }
    for (int32_t i = 0; i < m->n_nodes; i++)
        r->unused_nodes += !used[i];
    free(used);
    int32_t *adj = fs_malloc((4 * (size_t)m->n_tets + 1) * sizeof *adj);
    r->bad_faces = fs_tetmesh_adjacency(m, adj);
    for (int32_t h = 0; h < 4 * m->n_tets; h++)
        r->boundary_faces += adj[h] < 0;
    int32_t *comp = fs_malloc(((size_t)m->n_tets + 1) * sizeof *comp);
    r->components = fs_tetmesh_components(m, adj, comp);
    free(comp);
    free(adj);
    static const int ecs[6][3] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    int64_t faces = count_distinct(m, 4, fs_tet_face, 3, face_key_of);
    int64_t edges = count_distinct(m, 6, ecs, 2, edge_key_of);
    r->euler = (int64_t)(m->n_nodes - r->unused_nodes) - edges + faces - m->n_tets;
    return r->bad_faces == 0 && r->nonpositive == 0 && r->unused_nodes == 0 ? 0 : -1;
}

/* ---- the layered mesher ---- */

fs_tetlayer_params fs_tetlayer_params_default(void)
{
    fs_tetlayer_params p = {.thickness = 1.0, .layers = 1, .iterations = 30, .radius_jitter = 0.2, .seed = 1,
                            .sliver_quality = 0.05};
    return p;
}

/* Sliver rounds: move the corners of slivers and triangulate again at most this often. */
#define SLIVER_ROUNDS 2
/* A move is at most this many spacings. */
#define SLIVER_MOVE 0.15
/* Layer spacing in the isotropic frame, in spacings (close packing: sqrt(2/3)). */
#define LAYER_SPACING 0.8165
/* Most the radial stretch may exceed the true thickness on the sphere, relative to the radius. */
#define SPHERE_STRETCH 0.05
/* Points closer than this many spacings to a side that does not wrap are moved onto it. */
#define SIDE_SNAP 0.1
/* Offset of each point across its layer in the isotropic frame, in spacings: it breaks the ties of
 * coplanar (cospherical) layers, which make Qhull slow, without changing the mesh otherwise. */
#define LAYER_JIGGLE 1e-6

/* The point of layer k at domain point p: material coordinates (mat) and isotropic-frame coordinates
 * (iso), given the heights h_mat and h_iso of the top and the tie-breaking offset jiggle (cm) of the
 * isotropic point across its layer. */
static void layer_point(const fs_domain *d, const double *p, double zeta, double h_mat, double h_iso, double jiggle,
                        double *mat, double *iso)
{
    if (d->type == FS_DOMAIN_SPHERE) {
        double r = fs_norm3(p);
        for (int k = 0; k < 3; k++) {
            mat[k] = p[k] / r * (d->radius + zeta * h_mat);
            iso[k] = p[k] / r * (d->radius + zeta * h_iso + jiggle);
        }
        return;
    }
    mat[0] = iso[0] = p[0];
    mat[1] = iso[1] = p[1];
    mat[2] = zeta * h_mat;
    iso[2] = zeta * h_iso + jiggle;
}

/* Whether the corners of tetrahedron t all lie on one bounding surface of the layer: its top, its
 * bottom, or a side of a plane that does not wrap (such a tetrahedron is flat, a cap of points that
 * are coplanar there). */
static bool on_one_surface(const fs_tetmesh *m, const int32_t *layer, int top, int32_t t)
{
    const int32_t *v = m->tet + 4 * (size_t)t;
    bool same_layer = layer[v[0]] == layer[v[1]] && layer[v[0]] == layer[v[2]] && layer[v[0]] == layer[v[3]];
    if (same_layer && (layer[v[0]] == 0 || layer[v[0]] == top))
        return true;
    if (m->domain.type == FS_DOMAIN_SPHERE)
        return false;
    for (int k = 0; k < 2; k++) {
        if (m->period[k] > 0.0)
            continue;
        double ext = k == 0 ? fs_domain_extent_x(&m->domain) : fs_domain_extent_y(&m->domain);
        for (int side = 0; side < 2; side++) {
            double at = side ? ext : 0.0;
            bool all = true;
            for (int c = 0; c < 4; c++)
                all = all && m->pos[3 * (size_t)v[c] + k] == at;
            if (all)
                return true;
        }
    }
    return false;
}

/* The expected volume of one period of the layer when it is a box (a slab wrapping both ways), else 0:
 * other sides are the hull of sampled points, checked through the faces alone. */
static double layer_volume(const fs_tetmesh *m)
{
    if (m->domain.type == FS_DOMAIN_SPHERE || !(m->period[0] > 0.0) || !(m->period[1] > 0.0))
        return 0.0;
    return m->period[0] * m->period[1] * m->thickness;
}

/* Triangulates the isotropic-frame points into m's tetrahedra, growing the margin until the faces
 * match and, where known, the volume of one period is filled. layer[i]: the layer of node i, top the
 * top layer's number; tetrahedra on one bounding surface are dropped (on_one_surface; on the sphere
 * these include the hollow's). */
static int triangulate(fs_tetmesh *m, const double *iso, const int32_t *layer, int top, double spacing, double h_iso)
{
    double margin = 3.0 * spacing;
    double limit = 4.0 * fmax(fmax(m->period[0], m->period[1]), h_iso) + 8.0 * spacing;
    double want = layer_volume(m);
    bool merge = false;
    for (;;) {
        fs_tets tets;
        if (fs_delaunay_tets(iso, m->n_nodes, m->period, margin, merge, &tets) < 0)
            return -1;
        free(m->tet);
        free(m->shift);
        m->tet = NULL;
        m->shift = NULL;
        m->n_tets = m->cap_tets = 0;
        for (int32_t t = 0; t < tets.n_tets; t++) {
            int32_t at = fs_tetmesh_add_tet(m, tets.tet + 4 * (size_t)t, tets.shift + 8 * (size_t)t);
            if (on_one_surface(m, layer, top, at))
                m->n_tets--;
        }
        fs_tets_free(&tets);
        int32_t *adj = fs_malloc((4 * (size_t)m->n_tets + 1) * sizeof *adj);
        int32_t bad = fs_tetmesh_adjacency(m, adj);
        /* on a wrapping axis no boundary face may face along the axis */
        for (int32_t h = 0; h < 4 * m->n_tets && !bad; h++) {
            if (adj[h] >= 0)
                continue;
            double x[12], e1[3], e2[3], n[3];
            fs_tetmesh_corners(m, h / 4, x);
            const int *f = fs_tet_face[h % 4];
            fs_sub3(e1, x + 3 * f[1], x + 3 * f[0]);
            fs_sub3(e2, x + 3 * f[2], x + 3 * f[0]);
            fs_cross3(n, e1, e2);
            for (int d = 0; d < 2; d++)
                if (m->period[d] > 0.0 && fabs(n[d]) > 1e-9 * fs_norm3(n))
                    bad++;
        }
        free(adj);
        double vol = 0.0;
        for (int32_t t = 0; t < m->n_tets; t++)
            vol += fs_tetmesh_volume(m, t);
        if (!bad && (want <= 0.0 || fabs(vol - want) <= 1e-9 * want))
            return 0;
        if (!merge) {
            merge = true;
            continue;
        }
        if (margin >= limit) {
            fs_error(FS_ERR_INTERNAL, "tetmesh: no consistent periodic tetrahedralization of %d points (%d faces "
                     "unmatched, volume %g of %g)", (int)m->n_nodes, (int)bad, vol, want);
            return -1;
        }
        margin = fmin(2.0 * margin, limit);
    }
}

int fs_tetmesh_layer(const fs_domain *d, const fs_points *top, const fs_tetlayer_params *p, fs_tetmesh *out)
{
    memset(out, 0, sizeof *out);
    fs_domain dom = *d;
    fs_domain_normalize(&dom);
    if (!(p->thickness > 0.0) || !isfinite(p->thickness) || p->layers < 1 || p->layers > 64) {
        fs_error(FS_ERR_DATA, "tetmesh: thickness %g cm and %d layers: expected a positive thickness and 1 to 64 "
                 "layers", p->thickness, p->layers);
        return -1;
    }
    if (!top || top->n < 4) {
        fs_error(FS_ERR_DATA, "tetmesh: %d points on the top: expected at least 4", top ? (int)top->n : 0);
        return -1;
    }
    int32_t per = top->n, nl = p->layers + 1;
    if ((int64_t)per * nl > INT32_MAX / 4) {
        fs_error(FS_ERR_DATA, "tetmesh: %d points in %d layers are too many", (int)per, (int)nl);
        return -1;
    }
    out->domain = dom;
    out->thickness = p->thickness;
    if (dom.type != FS_DOMAIN_SPHERE) {
        out->period[0] = dom.type == FS_DOMAIN_CYLINDER || dom.periodic_x ? fs_domain_extent_x(&dom) : 0.0;
        out->period[1] = dom.periodic_y ? fs_domain_extent_y(&dom) : 0.0;
    }
    double spacing = fs_sample_spacing(&dom, per);
    double h_iso = LAYER_SPACING * spacing * p->layers;
    if (dom.type == FS_DOMAIN_SPHERE)
        h_iso = fmin(h_iso, p->thickness + SPHERE_STRETCH * dom.radius);

    /* the point layers: the top as given, the others sampled afresh */
    double *flat = fs_malloc(3 * (size_t)per * nl * sizeof *flat);
    int32_t *layer = fs_malloc((size_t)per * nl * sizeof *layer);
    for (int k = 0; k < nl; k++) {
        fs_points pts = {0};
        const fs_points *src = top;
        if (k < nl - 1) {
            fs_sample_params sp = fs_sample_params_default();
            sp.count = per;
            sp.iterations = p->iterations;
            sp.radius_jitter = p->radius_jitter;
            sp.seed = fs_hash3(p->seed, FS_RNG_SAMPLE_INIT, 0x7e700000u + (uint64_t)k);
            if (fs_sample_repulsion(&dom, &sp, &pts) < 0 || pts.n != per) {
                fs_points_free(&pts);
                free(flat);
                free(layer);
                if (fs_error_domain() == FS_OK)
                    fs_error(FS_ERR_INTERNAL, "tetmesh: layer %d has a different number of points", k);
                return -1;
            }
            src = &pts;
        }
        for (int32_t i = 0; i < per; i++) {
            double q[3];
            memcpy(q, src->p + 3 * (size_t)i, sizeof q);
            if (dom.type != FS_DOMAIN_SPHERE) {
                fs_domain_wrap(&dom, q);
                /* a point next to a side that does not wrap goes onto it (else it makes a sliver there) */
                for (int a = 0; a < 2; a++) {
                    double ext = a == 0 ? fs_domain_extent_x(&dom) : fs_domain_extent_y(&dom);
                    if (out->period[a] > 0.0)
                        continue;
                    if (q[a] < SIDE_SNAP * spacing)
                        q[a] = 0.0;
                    else if (q[a] > ext - SIDE_SNAP * spacing)
                        q[a] = ext;
                }
            }
            memcpy(flat + 3 * ((size_t)k * per + i), q, sizeof q);
            layer[(size_t)k * per + i] = k;
        }
        fs_points_free(&pts);
    }
    double *iso = fs_malloc(3 * (size_t)per * nl * sizeof *iso);
    for (int32_t i = 0; i < per * nl; i++) {
        double zeta = (double)layer[i] / p->layers, mat[3];
        double jiggle = LAYER_JIGGLE * spacing * fs_rand_range(p->seed, FS_RNG_SAMPLE_INIT, (uint64_t)i, -1.0, 1.0);
        layer_point(&dom, flat + 3 * (size_t)i, zeta, p->thickness, h_iso, jiggle, mat, iso + 3 * (size_t)i);
        fs_tetmesh_add_node(out, mat, layer[i] == 0 ? 0.0 : (layer[i] == p->layers ? 1.0 : zeta));
    }

    int rc = 0;
    int32_t slivers = 0;
    for (int round = 0;; round++) {
        if ((rc = triangulate(out, iso, layer, p->layers, spacing, h_iso)) < 0)
            break;
        /* slivers in the isotropic frame (and any tetrahedron the return to true heights flattened) */
        uint8_t *move = fs_calloc((size_t)out->n_nodes, 1);
        slivers = 0;
        for (int32_t t = 0; t < out->n_tets; t++) {
            double x[12];
            for (int c = 0; c < 4; c++) {
                int32_t v = out->tet[4 * (size_t)t + c];
                const int8_t *s = out->shift + 8 * (size_t)t + 2 * c;
                x[3 * c] = iso[3 * (size_t)v] + s[0] * out->period[0];
                x[3 * c + 1] = iso[3 * (size_t)v + 1] + s[1] * out->period[1];
                x[3 * c + 2] = iso[3 * (size_t)v + 2];
            }
            if (fs_tet_quality(x) >= p->sliver_quality && fs_tetmesh_volume(out, t) > 0.0)
                continue;
            slivers++;
            for (int c = 0; c < 4; c++)
                move[out->tet[4 * (size_t)t + c]] = 1;
        }
        if (slivers == 0 || round == SLIVER_ROUNDS) {
            free(move);
            break;
        }
        /* move the sliver corners within their layers, by hashed steps that differ each round */
        for (int32_t i = 0; i < out->n_nodes; i++) {
            if (!move[i])
                continue;
            uint64_t id = ((uint64_t)round << 40) ^ (uint64_t)i;
            double step[3];
            for (int k = 0; k < 3; k++)
                step[k] = SLIVER_MOVE * spacing * fs_rand_range(p->seed, FS_RNG_SAMPLE_INIT, 3 * id + k, -1.0, 1.0);
            double *q = flat + 3 * (size_t)i;
            if (dom.type == FS_DOMAIN_SPHERE) {
                double r = fs_norm3(q), nrm[3] = {q[0] / r, q[1] / r, q[2] / r}, along = fs_dot3(step, nrm);
                for (int k = 0; k < 3; k++)
                    q[k] += step[k] - along * nrm[k];
                double r2 = fs_norm3(q);
                for (int k = 0; k < 3; k++)
                    q[k] *= dom.radius / r2;
            } else {
                /* points on a side that does not wrap stay on it */
                for (int k = 0; k < 2; k++) {
                    double ext = k == 0 ? fs_domain_extent_x(&dom) : fs_domain_extent_y(&dom);
                    bool wraps = out->period[k] > 0.0;
                    if (!wraps && (q[k] <= 0.0 || q[k] >= ext))
                        continue;
                    q[k] += step[k];
                    if (!wraps)
                        q[k] = fmin(fmax(q[k], 0.0), ext); /* snapped onto a side it crossed */
                }
                fs_domain_wrap(&dom, q);
            }
            double jiggle = LAYER_JIGGLE * spacing * fs_rand_range(p->seed, FS_RNG_SAMPLE_INIT, (uint64_t)i, -1.0, 1.0);
            layer_point(&dom, q, out->zeta[i], p->thickness, h_iso, jiggle, out->pos + 3 * (size_t)i,
                        iso + 3 * (size_t)i);
        }
        free(move);
    }
    if (rc == 0) {
        /* faces were checked by triangulate; the return to true heights keeps volumes positive on the
         * plane and the cylinder, and nearly always on the sphere */
        int32_t bad = 0;
        double qmin = INFINITY;
        for (int32_t t = 0; t < out->n_tets; t++) {
            double x[12];
            fs_tetmesh_corners(out, t, x);
            bad += !(fs_tet_volume(x) > 0.0);
            qmin = fmin(qmin, fs_tet_quality(x));
        }
        if (bad) {
            fs_error(FS_ERR_INTERNAL, "tetmesh: %d tetrahedra of the layer have no volume (a shell too thick for "
                     "its radius?)", (int)bad);
            rc = -1;
        } else {
            fs_debug("tetmesh: %d nodes in %d layers, %d tetrahedra, %d slivers left, smallest quality %.3g",
                     (int)out->n_nodes, (int)nl, (int)out->n_tets, (int)slivers, qmin);
        }
    }
    free(flat);
    free(layer);
    free(iso);
    if (rc < 0)
        fs_tetmesh_free(out);
    return rc;
}
