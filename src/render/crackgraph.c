/* The crack graph of a rendered raster: skeleton, tracing, pruning, simplification, fragments (see crackgraph.h). */
#include "render/crackgraph.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/vec.h"
#include "image/image.h"

fs_crackgraph_params fs_crackgraph_params_default(void)
{
    return (fs_crackgraph_params){
        .crack_threshold = 0.5f, .min_island = 8, .simplify = 0.75, .spur_ratio = 2.5, .min_spur = 3.0,
        .min_contact = 2};
}

/* The 8 neighbours in ring order (each 8-adjacent to the next, the last to the first); y grows
 * downwards (rows). Bit k of a neighbourhood code is neighbour k. */
static const int ring_dx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int ring_dy[8] = {0, -1, -1, -1, 0, 1, 1, 1};

/* A grid that wraps on some axes; off-grid neighbours on the other axes do not exist. */
typedef struct {
    int w, h;
    bool wrap_u, wrap_v;
} grid;

/* Index of (x + dx, y + dy), or -1 when it leaves a non-wrapping axis. */
static int32_t grid_step(const grid *g, int x, int y, int dx, int dy)
{
    x += dx;
    y += dy;
    if (x < 0 || x >= g->w) {
        if (!g->wrap_u)
            return -1;
        x = (x + g->w) % g->w;
    }
    if (y < 0 || y >= g->h) {
        if (!g->wrap_v)
            return -1;
        y = (y + g->h) % g->h;
    }
    return (int32_t)y * g->w + x;
}

static unsigned neighbour_code(const grid *g, const uint8_t *fg, int32_t k)
{
    int x = k % g->w, y = k / g->w;
    unsigned code = 0;
    for (int r = 0; r < 8; r++) {
        int32_t n = grid_step(g, x, y, ring_dx[r], ring_dy[r]);
        if (n >= 0 && fg[n])
            code |= 1u << r;
    }
    return code;
}

static int popcount8(unsigned c)
{
    int n = 0;
    for (; c; c &= c - 1)
        n++;
    return n;
}

/* design: a pixel is simple (deleting it changes no topology, with 8-connected cracks and
 * 4-connected background) when its foreground neighbours form exactly one 8-connected set and its
 * background neighbours exactly one 4-connected set touching a 4-neighbour of the pixel. The
 * components are counted on the 3 x 3 neighbourhood without the centre, for all 256 codes. */
static void simple_table(bool simple[256])
{
    for (unsigned code = 0; code < 256; code++) {
        int fg_comp = 0, bg_comp = 0;
        int seen = 0; /* bit r: ring position r already labelled */
        for (int r = 0; r < 8; r++) {
            bool is_fg = code >> r & 1u;
            if (seen >> r & 1)
                continue;
            /* Flood the component of r among the same-valued ring positions. */
            int stack[8], top = 0;
            stack[top++] = r;
            seen |= 1 << r;
            bool touches_4 = false;
            while (top) {
                int a = stack[--top];
                if (ring_dx[a] == 0 || ring_dy[a] == 0)
                    touches_4 = true;
                for (int b = 0; b < 8; b++) {
                    if ((seen >> b & 1) || (bool)(code >> b & 1u) != is_fg)
                        continue;
                    int ddx = abs(ring_dx[a] - ring_dx[b]), ddy = abs(ring_dy[a] - ring_dy[b]);
                    bool adjacent = is_fg ? (ddx <= 1 && ddy <= 1) : (ddx + ddy == 1);
                    if (adjacent) {
                        seen |= 1 << b;
                        stack[top++] = b;
                    }
                }
            }
            if (is_fg)
                fg_comp++;
            else if (touches_4)
                bg_comp++;
        }
        simple[code] = fg_comp == 1 && bg_comp == 1;
    }
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static bool has_background_4(const grid *g, const uint8_t *fg, int32_t k)
{
    static const int dx[4] = {0, 0, -1, 1}, dy[4] = {-1, 1, 0, 0};
    const int x = k % g->w, y = k / g->w;
    for (int d = 0; d < 4; d++) {
        int32_t b = grid_step(g, x, y, dx[d], dy[d]);
        if (b < 0 || !fg[b])
            return true;
    }
    return false;
}

/* Sequential thinning by directional passes (north, south, west, east border pixels, found at the
 * start of each pass and visited in raster order), deleting simple pixels that are not free ends
 * until nothing changes. Only border pixels (with a background 4-neighbour) are kept in the work
 * list, and a deletion adds its neighbours, so the cost is proportional to the crack area rather
 * than to the area times the crack width. */
static void thin(const grid *g, uint8_t *fg)
{
    bool simple[256];
    simple_table(simple);
    size_t n = (size_t)g->w * (size_t)g->h;
    uint8_t *listed = fs_calloc(n, 1);
    size_t cap = 1024, n_border = 0;
    int32_t *border = fs_malloc(cap * sizeof *border);
    for (size_t k = 0; k < n; k++)
        if (fg[k] && has_background_4(g, fg, (int32_t)k)) {
            FS_ARRAY_RESERVE(border, cap, n_border + 1, 1024);
            border[n_border++] = (int32_t)k;
            listed[k] = 1;
        }
    int32_t *cand = fs_malloc(cap * sizeof *cand);
    size_t cap_cand = cap;
    static const int dir_dx[4] = {0, 0, -1, 1}, dir_dy[4] = {-1, 1, 0, 0};
    for (bool changed = true; changed;) {
        changed = false;
        for (int d = 0; d < 4; d++) {
            if (cap_cand < n_border) {
                cap_cand = cap;
                cand = fs_realloc(cand, cap_cand * sizeof *cand);
            }
            size_t n_cand = 0;
            for (size_t i = 0; i < n_border; i++) {
                int32_t k = border[i];
                int32_t b = grid_step(g, k % g->w, k / g->w, dir_dx[d], dir_dy[d]);
                if (b < 0 || !fg[b])
                    cand[n_cand++] = k;
            }
            qsort(cand, n_cand, sizeof *cand, cmp_i32);
            for (size_t i = 0; i < n_cand; i++) {
                int32_t k = cand[i];
                unsigned code = neighbour_code(g, fg, k);
                if (popcount8(code) < 2 || !simple[code])
                    continue;
                fg[k] = 0;
                changed = true;
                /* Its foreground neighbours now touch the background. */
                for (int r = 0; r < 8; r += 2) {
                    int32_t q = grid_step(g, k % g->w, k / g->w, ring_dx[r], ring_dy[r]);
                    if (q < 0 || !fg[q] || listed[q])
                        continue;
                    FS_ARRAY_RESERVE(border, cap, n_border + 1, 1024);
                    border[n_border++] = q;
                    listed[q] = 1;
                }
            }
            size_t m = 0;
            for (size_t i = 0; i < n_border; i++) {
                if (fg[border[i]])
                    border[m++] = border[i];
                else
                    listed[border[i]] = 0;
            }
            n_border = m;
        }
    }
    free(listed);
    free(border);
    free(cand);
}

/* ---- tracing ---- */

typedef struct {
    double x, y;             /* pixel units, unwrapped; pixel (i, j) has its centre at (i + .5, j + .5) */
} pt;

typedef struct {
    int32_t node[2];         /* -1 on a closed line */
    int32_t first, n;        /* into the point and pixel pools */
    bool dead;
} tedge;

typedef struct {
    double x, y;             /* position in pixels, in [0, w) x [0, h) (border nodes may sit on w or h) */
    double half_width;       /* crack half-width at the node (pixels) */
    fs_crack_node_kind kind;
    int32_t degree;
    bool dead;
} tnode;

typedef struct {
    grid g;
    const uint8_t *sk;       /* skeleton */
    const uint8_t *outward;  /* skeleton pixel continues past a non-wrapping border */
    uint8_t *stub;           /* a line through the pixel branches off out of the border there */
    const float *dist;       /* distance from a crack pixel to the nearest non-crack pixel */
    int32_t *count;          /* skeleton neighbours */
    int32_t *cluster;        /* junction node of a junction pixel, -1 otherwise */
    uint8_t *visited;
    tnode *node;
    int32_t n_nodes, cap_nodes;
    tedge *edge;
    int32_t n_edges, cap_edges;
    pt *pts;                 /* path points (nodes and pixel centres) */
    int32_t *pix;            /* pixel of each path point, -1 for a node point */
    int32_t n_pts, cap_pts;
} tracer;

static int32_t add_node(tracer *t, double x, double y, double half_width, fs_crack_node_kind kind)
{
    FS_ARRAY_RESERVE(t->node, t->cap_nodes, t->n_nodes + 1, 256);
    t->node[t->n_nodes] = (tnode){x, y, half_width, kind, 0, false};
    return t->n_nodes++;
}

static void add_point(tracer *t, double x, double y, int32_t pixel)
{
    if (FS_ARRAY_GROW(t->cap_pts, t->n_pts + 1, 4096)) {
        FS_ARRAY_RESIZE(t->pts, t->cap_pts);
        FS_ARRAY_RESIZE(t->pix, t->cap_pts);
    }
    t->pts[t->n_pts] = (pt){x, y};
    t->pix[t->n_pts++] = pixel;
}

static int32_t add_edge(tracer *t, int32_t a, int32_t b, int32_t first)
{
    FS_ARRAY_RESERVE(t->edge, t->cap_edges, t->n_edges + 1, 256);
    t->edge[t->n_edges] = (tedge){{a, b}, first, t->n_pts - first, false};
    return t->n_edges++;
}

/* Value of x shifted by whole periods to lie nearest to ref (on a wrapping axis). */
static double unwrap_near(double x, double ref, double period, bool wrap)
{
    return wrap ? x + period * floor((ref - x) / period + 0.5) : x;
}

static double half_width_at(const tracer *t, int32_t k)
{
    double d = t->dist[k] - 0.5;
    return d > 0.5 ? d : 0.5;
}

/* A node on the non-wrapping border nearest to pixel k (its projection onto it). */
static int32_t border_node(tracer *t, int32_t k)
{
    const grid *g = &t->g;
    double px = k % g->w + 0.5, py = (double)(k / g->w) + 0.5;
    double best = INFINITY;
    double bx = px, by = py;
    if (!g->wrap_u) {
        if (px < best) best = px, bx = 0.0, by = py;
        if (g->w - px < best) best = g->w - px, bx = g->w, by = py;
    }
    if (!g->wrap_v) {
        if (py < best) best = py, bx = px, by = 0.0;
        if (g->h - py < best) best = g->h - py, bx = px, by = g->h;
    }
    return add_node(t, bx, by, half_width_at(t, k), FS_CRACK_BORDER);
}

/* The free end at pixel k: on the border when the skeleton ran on past a non-wrapping border
 * there, else a crack tip. */
static int32_t end_node(tracer *t, int32_t k)
{
    if (t->outward[k])
        return border_node(t, k);
    return add_node(t, k % t->g.w + 0.5, (double)(k / t->g.w) + 0.5, half_width_at(t, k), FS_CRACK_END);
}

/* Adds a node's position to the path, unwrapped near (x, y). */
static void add_node_point(tracer *t, int32_t node, double x, double y)
{
    const tnode *nd = &t->node[node];
    add_point(t, unwrap_near(nd->x, x, t->g.w, t->g.wrap_u), unwrap_near(nd->y, y, t->g.h, t->g.wrap_v), -1);
}

/* Walks from pixel k (unwrapped centre x, y), having come from pixel prev (-1 for none), until a
 * junction, a free end or the start of a closed line, and adds the branch from start_node (-1 on a
 * closed line) whose path begins at point `first` (the start node's point, already added when it
 * is not pixel k itself). Returns the edge. */
static int32_t walk(tracer *t, int32_t start_node, int32_t first, int32_t k, int32_t prev, double x, double y)
{
    const grid *g = &t->g;
    const int32_t start_pixel = k;
    for (;;) {
        t->visited[k] = 1;
        add_point(t, x, y, k);
        int kx = k % g->w, ky = k / g->w;
        /* Off the skeleton's junctions every pixel has at most two neighbours: the one we came
         * from and the next (the first in ring order when starting on a closed line). */
        int32_t next = -1;
        int nr = -1;
        for (int r = 0; r < 8 && next < 0; r++) {
            int32_t q = grid_step(g, kx, ky, ring_dx[r], ring_dy[r]);
            if (q >= 0 && t->sk[q] && q != prev) {
                next = q;
                nr = r;
            }
        }
        if (next < 0) {
            int32_t end = end_node(t, k);
            add_node_point(t, end, x, y);
            if (t->pts[t->n_pts - 1].x == x && t->pts[t->n_pts - 1].y == y)
                t->n_pts--; /* a crack tip sits on its pixel: no repeated point */
            return add_edge(t, start_node, end, first);
        }
        double nx = x + ring_dx[nr], ny = y + ring_dy[nr];
        if (t->cluster[next] >= 0) {
            add_node_point(t, t->cluster[next], nx, ny);
            return add_edge(t, start_node, t->cluster[next], first);
        }
        if (t->visited[next]) {
            if (next == start_pixel && start_node < 0) {
                add_point(t, nx, ny, next); /* closed: repeat the first point */
                return add_edge(t, -1, -1, first);
            }
            int32_t end = add_node(t, x, y, half_width_at(t, k), FS_CRACK_END);
            add_node_point(t, end, x, y);
            t->n_pts--;
            return add_edge(t, start_node, end, first);
        }
        prev = k;
        k = next;
        x = nx;
        y = ny;
    }
}

/* Labels junction pixels (three or more skeleton neighbours) into 8-connected clusters, one node each. */
static void find_junctions(tracer *t)
{
    const grid *g = &t->g;
    size_t n = (size_t)g->w * (size_t)g->h;
    int32_t *stack = fs_malloc(n * sizeof *stack);
    for (size_t k0 = 0; k0 < n; k0++) {
        if (!t->sk[k0] || t->count[k0] < 3 || t->cluster[k0] >= 0)
            continue;
        int32_t node = add_node(t, 0, 0, 0, FS_CRACK_JUNCTION);
        double sx = 0, sy = 0, hw = 0.5;
        int32_t m = 0, top = 0;
        double ox = (double)(k0 % g->w) + 0.5, oy = (double)(k0 / g->w) + 0.5;
        t->cluster[k0] = node;
        stack[top++] = (int32_t)k0;
        while (top) {
            int32_t k = stack[--top];
            double px = unwrap_near(k % g->w + 0.5, ox, g->w, g->wrap_u);
            double py = unwrap_near(k / g->w + 0.5, oy, g->h, g->wrap_v);
            sx += px;
            sy += py;
            m++;
            hw = fmax(hw, half_width_at(t, k));
            for (int r = 0; r < 8; r++) {
                int32_t q = grid_step(g, k % g->w, k / g->w, ring_dx[r], ring_dy[r]);
                if (q >= 0 && t->sk[q] && t->count[q] >= 3 && t->cluster[q] < 0) {
                    t->cluster[q] = node;
                    stack[top++] = q;
                }
            }
        }
        double cx = sx / m, cy = sy / m;
        if (g->wrap_u)
            cx -= g->w * floor(cx / g->w);
        if (g->wrap_v)
            cy -= g->h * floor(cy / g->h);
        t->node[node].x = cx;
        t->node[node].y = cy;
        t->node[node].half_width = hw;
    }
    free(stack);
}

static void trace_all(tracer *t)
{
    const grid *g = &t->g;
    size_t n = (size_t)g->w * (size_t)g->h;
    /* Branches leaving junction clusters, in raster order of the junction pixels. */
    for (size_t k = 0; k < n; k++) {
        if (!t->sk[k] || t->cluster[k] < 0)
            continue;
        int32_t node = t->cluster[k];
        int kx = (int)(k % g->w), ky = (int)(k / g->w);
        if (t->stub[k]) {
            int32_t first = t->n_pts, end = border_node(t, (int32_t)k);
            add_node_point(t, node, kx + 0.5, ky + 0.5);
            add_node_point(t, end, kx + 0.5, ky + 0.5);
            add_edge(t, node, end, first);
        }
        for (int r = 0; r < 8; r++) {
            int32_t q = grid_step(g, kx, ky, ring_dx[r], ring_dy[r]);
            if (q < 0 || !t->sk[q] || t->cluster[q] >= 0 || t->visited[q])
                continue;
            double x = kx + 0.5 + ring_dx[r], y = ky + 0.5 + ring_dy[r];
            int32_t first = t->n_pts;
            add_node_point(t, node, kx + 0.5, ky + 0.5);
            walk(t, node, first, q, (int32_t)k, x, y);
        }
    }
    /* Lines between two free ends. */
    for (size_t k = 0; k < n; k++) {
        if (!t->sk[k] || t->visited[k] || t->count[k] != 1)
            continue;
        double x = k % g->w + 0.5, y = (double)(k / g->w) + 0.5;
        int32_t start = end_node(t, (int32_t)k);
        int32_t first = t->n_pts;
        add_node_point(t, start, x, y);
        if (t->node[start].kind == FS_CRACK_END)
            t->n_pts--;
        walk(t, start, first, (int32_t)k, -1, x, y);
    }
    /* What is left are closed lines without junctions. */
    for (size_t k = 0; k < n; k++) {
        if (!t->sk[k] || t->visited[k] || t->count[k] != 2)
            continue;
        walk(t, -1, t->n_pts, (int32_t)k, -1, k % g->w + 0.5, (double)(k / g->w) + 0.5);
    }
}

/* ---- pruning ---- */

static double path_length(const tracer *t, const tedge *e)
{
    double len = 0.0;
    for (int32_t i = 1; i < e->n; i++) {
        const pt *a = &t->pts[e->first + i - 1], *b = &t->pts[e->first + i];
        len += hypot(b->x - a->x, b->y - a->y);
    }
    return len;
}

static void count_degrees(tracer *t)
{
    for (int32_t i = 0; i < t->n_nodes; i++)
        t->node[i].degree = 0;
    for (int32_t i = 0; i < t->n_edges; i++) {
        const tedge *e = &t->edge[i];
        if (e->dead)
            continue;
        for (int s = 0; s < 2; s++)
            if (e->node[s] >= 0)
                t->node[e->node[s]].degree++;
    }
}

/* Appends edge e's path to the pools, reversed when reverse, shifted by (dx, dy), skipping the
 * first `skip` points. */
static void copy_path(tracer *t, int32_t e, bool reverse, double dx, double dy, int skip)
{
    const int32_t first = t->edge[e].first, n = t->edge[e].n;
    for (int32_t i = skip; i < n; i++) {
        int32_t j = reverse ? first + n - 1 - i : first + i;
        pt p = t->pts[j];
        add_point(t, p.x + dx, p.y + dy, t->pix[j]);
    }
}

/* Joins branches e1 and e2 through degree-2 node v into one (a loop through v, e1 == e2, becomes
 * closed). Returns the new edge. */
static int32_t merge_at(tracer *t, int32_t v, int32_t e1, int32_t e2)
{
    FS_ASSERT(e1 >= 0 && e2 >= 0);
    int32_t first = t->n_pts, merged;
    if (e1 == e2) {
        copy_path(t, e1, false, 0, 0, 0);
        t->edge[e1].dead = true;
        merged = add_edge(t, -1, -1, first);
    } else {
        /* e1 runs into v, e2 out of v. */
        bool rev1 = t->edge[e1].node[0] == v, rev2 = t->edge[e2].node[1] == v;
        copy_path(t, e1, rev1, 0, 0, 0);
        pt join = t->pts[t->n_pts - 1];
        const tedge *b = &t->edge[e2];
        pt start = t->pts[rev2 ? b->first + b->n - 1 : b->first];
        copy_path(t, e2, rev2, join.x - start.x, join.y - start.y, 1);
        int32_t a = t->edge[e1].node[rev1 ? 1 : 0], c = t->edge[e2].node[rev2 ? 0 : 1];
        t->edge[e1].dead = t->edge[e2].dead = true;
        merged = add_edge(t, a, c, first);
    }
    t->node[v].dead = true;
    return merged;
}

/* Removes skeleton noise: spurs from junctions to free ends, specks and tiny loops; then joins
 * branches through nodes left with two of them. */
static void prune(tracer *t, const fs_crackgraph_params *p)
{
    for (bool changed = true; changed;) {
        changed = false;
        count_degrees(t);
        for (int32_t i = 0; i < t->n_edges; i++) {
            tedge *e = &t->edge[i];
            if (e->dead)
                continue;
            double len = path_length(t, e);
            int32_t a = e->node[0], b = e->node[1];
            bool a_end = a >= 0 && t->node[a].kind == FS_CRACK_END;
            bool b_end = b >= 0 && t->node[b].kind == FS_CRACK_END;
            int32_t j = a_end ? b : a; /* the junction of a spur */
            bool spur = (a_end != b_end) && j >= 0 && t->node[j].kind == FS_CRACK_JUNCTION &&
                        len < fmax(p->min_spur, p->spur_ratio * t->node[j].half_width) &&
                        t->node[j].degree >= 2;
            bool speck = a_end && b_end && len < p->min_spur;
            bool loop = (a == b) && len < 2.0 * fmax(p->min_spur, p->spur_ratio *
                                                                     (a >= 0 ? t->node[a].half_width : 1.0));
            if (!spur && !speck && !loop)
                continue;
            e->dead = true;
            changed = true;
            for (int s = 0; s < 2; s++)
                if (e->node[s] >= 0)
                    t->node[e->node[s]].degree--;
            if (a_end)
                t->node[a].dead = true;
            if (b_end)
                t->node[b].dead = true;
        }
        count_degrees(t);
        /* The two branches at each node of degree 2, kept current as merges replace them (merging
         * leaves every other node's degree as it was). */
        int32_t *inc = fs_malloc(2 * ((size_t)t->n_nodes + 1) * sizeof *inc);
        for (int32_t v = 0; v < 2 * t->n_nodes; v++)
            inc[v] = -1;
        for (int32_t i = 0; i < t->n_edges; i++) {
            const tedge *e = &t->edge[i];
            for (int s = 0; s < 2 && !e->dead; s++) {
                int32_t v = e->node[s];
                if (v >= 0 && t->node[v].degree == 2)
                    inc[2 * v + (inc[2 * v] >= 0)] = i;
            }
        }
        for (int32_t v = 0; v < t->n_nodes; v++) {
            tnode *nd = &t->node[v];
            if (nd->dead)
                continue;
            if (nd->degree == 0) {
                nd->dead = true;
            } else if (nd->degree == 2) {
                int32_t e1 = inc[2 * v], e2 = inc[2 * v + 1];
                int32_t m = merge_at(t, v, e1, e2);
                for (int s = 0; s < 2; s++) {
                    int32_t w = t->edge[m].node[s];
                    for (int k = 0; w >= 0 && k < 2; k++)
                        if (inc[2 * w + k] == e1 || inc[2 * w + k] == e2)
                            inc[2 * w + k] = m;
                }
                changed = true;
            } else if (nd->degree == 1 && nd->kind == FS_CRACK_JUNCTION) {
                nd->kind = FS_CRACK_END;
                changed = true;
            }
        }
        free(inc);
    }
}

/* ---- simplification and output ---- */

/* Douglas-Peucker on path points [0, n): marks kept points in keep[]. */
static void simplify(const pt *p, int32_t n, double tol, uint8_t *keep, int32_t *stack)
{
    memset(keep, 0, (size_t)n);
    keep[0] = keep[n - 1] = 1;
    int32_t top = 0;
    stack[top++] = 0;
    stack[top++] = n - 1;
    while (top) {
        int32_t b = stack[--top], a = stack[--top];
        double dx = p[b].x - p[a].x, dy = p[b].y - p[a].y, len = hypot(dx, dy);
        double worst = -1.0;
        int32_t at = -1;
        for (int32_t i = a + 1; i < b; i++) {
            double ex = p[i].x - p[a].x, ey = p[i].y - p[a].y;
            double d = len > 0.0 ? fabs(ex * dy - ey * dx) / len : hypot(ex, ey);
            if (d > worst) {
                worst = d;
                at = i;
            }
        }
        if (at >= 0 && worst > tol) {
            keep[at] = 1;
            stack[top++] = a;
            stack[top++] = at;
            stack[top++] = at;
            stack[top++] = b;
        }
    }
}

typedef struct {
    fs_crackgraph *g;
    int32_t cap_pieces, cap_points, n_points;
} out_pools;

static void out_point(out_pools *o, double u, double v)
{
    if (FS_ARRAY_GROW(o->cap_points, o->n_points + 1, 4096))
        FS_ARRAY_RESIZE(o->g->point, 2 * (size_t)o->cap_points);
    u = u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
    v = v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
    o->g->point[2 * o->n_points] = u;
    o->g->point[2 * o->n_points + 1] = v;
    o->n_points++;
}

static void out_piece_start(out_pools *o)
{
    fs_crackgraph *g = o->g;
    FS_ARRAY_RESERVE(g->piece_start, o->cap_pieces, g->n_pieces + 2, 1024);
    g->piece_start[g->n_pieces++] = o->n_points;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Emits a simplified unwrapped polyline (texture units, v up) as pieces inside [0, 1]^2, cutting it
 * where it crosses a seam of a wrapping axis. */
static void emit_pieces(out_pools *o, const double *uv, int32_t n, bool wrap_u, bool wrap_v)
{
    double cell_u = NAN, cell_v = NAN;
    for (int32_t i = 0; i + 1 < n; i++) {
        const double *a = uv + 2 * i, *b = uv + 2 * i + 2;
        double ts[64];
        int nt = 0;
        ts[nt++] = 0.0;
        for (int axis = 0; axis < 2; axis++) {
            if (!(axis ? wrap_v : wrap_u))
                continue;
            double lo = fmin(a[axis], b[axis]), hi = fmax(a[axis], b[axis]);
            for (double s = ceil(lo); s < hi && nt < 62; s += 1.0)
                if (s > lo)
                    ts[nt++] = (s - a[axis]) / (b[axis] - a[axis]);
        }
        qsort(ts + 1, (size_t)(nt - 1), sizeof *ts, cmp_double);
        ts[nt++] = 1.0;
        for (int k = 0; k + 1 < nt; k++) {
            double t0 = ts[k], t1 = ts[k + 1];
            double p0[2] = {a[0] + (b[0] - a[0]) * t0, a[1] + (b[1] - a[1]) * t0};
            double p1[2] = {a[0] + (b[0] - a[0]) * t1, a[1] + (b[1] - a[1]) * t1};
            double mu = wrap_u ? floor(0.5 * (p0[0] + p1[0])) : 0.0;
            double mv = wrap_v ? floor(0.5 * (p0[1] + p1[1])) : 0.0;
            if (!(mu == cell_u && mv == cell_v)) {
                out_piece_start(o);
                out_point(o, p0[0] - mu, p0[1] - mv);
                cell_u = mu;
                cell_v = mv;
            }
            out_point(o, p1[0] - mu, p1[1] - mv);
        }
    }
}

/* ---- fragments ---- */

/* Turns 4-connected islands of material smaller than min_island pixels into crack. */
static void fill_islands(const grid *g, uint8_t *mask, int32_t min_island)
{
    size_t n = (size_t)g->w * (size_t)g->h;
    uint8_t *seen = fs_calloc(n, 1);
    int32_t *stack = fs_malloc(n * sizeof *stack), *comp = fs_malloc(n * sizeof *comp);
    static const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (size_t k0 = 0; k0 < n; k0++) {
        if (mask[k0] || seen[k0])
            continue;
        int32_t top = 0, m = 0;
        stack[top++] = (int32_t)k0;
        seen[k0] = 1;
        while (top) {
            int32_t k = stack[--top];
            comp[m++] = k;
            const int x = k % g->w, y = k / g->w;
            for (int s = 0; s < 4; s++) {
                int32_t q = grid_step(g, x, y, dx[s], dy[s]);
                if (q >= 0 && !mask[q] && !seen[q]) {
                    seen[q] = 1;
                    stack[top++] = q;
                }
            }
        }
        if (m < min_island)
            for (int32_t i = 0; i < m; i++)
                mask[comp[i]] = 1;
    }
    free(seen);
    free(stack);
    free(comp);
}

/* Grows the fragments of cell[] into the crack pixels (cell 0), breadth first, 8-connected. */
static void grow_labels(const grid *g, const uint16_t *cell, uint16_t *label)
{
    size_t n = (size_t)g->w * (size_t)g->h;
    int32_t *queue = fs_malloc(n * sizeof *queue);
    size_t head = 0, tail = 0;
    for (size_t k = 0; k < n; k++) {
        label[k] = cell[k];
        if (cell[k])
            queue[tail++] = (int32_t)k;
    }
    while (head < tail) {
        int32_t k = queue[head++];
        const int x = k % g->w, y = k / g->w;
        for (int r = 0; r < 8; r++) {
            int32_t q = grid_step(g, x, y, ring_dx[r], ring_dy[r]);
            if (q >= 0 && !label[q]) {
                label[q] = label[k];
                queue[tail++] = q;
            }
        }
    }
    free(queue);
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static int cmp_u16(const void *a, const void *b)
{
    uint16_t x = *(const uint16_t *)a, y = *(const uint16_t *)b;
    return (x > y) - (x < y);
}

/* Most frequent non-zero id among votes (the smallest on a tie); 0 when there is none. */
static uint16_t mode_u16(uint16_t *votes, size_t n)
{
    qsort(votes, n, sizeof *votes, cmp_u16);
    uint16_t best = 0;
    size_t best_n = 0;
    for (size_t i = 0; i < n;) {
        size_t j = i;
        while (j < n && votes[j] == votes[i])
            j++;
        if (votes[i] && j - i > best_n) {
            best = votes[i];
            best_n = j - i;
        }
        i = j;
    }
    return best;
}

static void build_fragments(const grid *g, const uint16_t *cell, const uint16_t *label, int32_t min_contact,
                            fs_crackgraph *out)
{
    int64_t *area = fs_calloc(65536, sizeof *area);
    double *sum = fs_calloc(4 * 65536, sizeof *sum); /* cos u, sin u (or u), cos v, sin v (or v) */
    /* Per column and per row: the coordinate, or its cosine and sine on a wrapping axis. */
    double *col = fs_malloc(2 * (size_t)g->w * sizeof *col), *row = fs_malloc(2 * (size_t)g->h * sizeof *row);
    for (int i = 0; i < g->w; i++) {
        double u = (i + 0.5) / g->w;
        col[2 * i] = g->wrap_u ? cos(2.0 * FS_PI * u) : u;
        col[2 * i + 1] = g->wrap_u ? sin(2.0 * FS_PI * u) : 0.0;
    }
    for (int j = 0; j < g->h; j++) {
        double v = 1.0 - (j + 0.5) / g->h;
        row[2 * j] = g->wrap_v ? cos(2.0 * FS_PI * v) : v;
        row[2 * j + 1] = g->wrap_v ? sin(2.0 * FS_PI * v) : 0.0;
    }
    for (int j = 0; j < g->h; j++)
        for (int i = 0; i < g->w; i++) {
            uint16_t id = cell[(size_t)j * g->w + i];
            if (!id)
                continue;
            area[id]++;
            double *s = sum + 4 * (size_t)id;
            s[0] += col[2 * i];
            s[1] += col[2 * i + 1];
            s[2] += row[2 * j];
            s[3] += row[2 * j + 1];
        }
    free(col);
    free(row);
    for (int id = 1; id < 65536; id++)
        out->n_fragments += area[id] > 0;
    out->fragment = fs_calloc((size_t)out->n_fragments + 1, sizeof *out->fragment);
    int32_t m = 0;
    for (int id = 1; id < 65536; id++) {
        if (!area[id])
            continue;
        const double *s = sum + 4 * (size_t)id;
        double cu, cv;
        if (g->wrap_u) {
            cu = atan2(s[1], s[0]) / (2.0 * FS_PI);
            cu -= floor(cu);
        } else {
            cu = s[0] / (double)area[id];
        }
        if (g->wrap_v) {
            cv = atan2(s[3], s[2]) / (2.0 * FS_PI);
            cv -= floor(cv);
        } else {
            cv = s[2] / (double)area[id];
        }
        out->fragment[m++] = (fs_crack_fragment){(uint16_t)id, area[id], {cu, cv}};
    }
    free(area);
    free(sum);

    /* Pairs of grown regions meeting across pixel edges (each edge once: right and down). */
    size_t cap = 4096, np = 0;
    uint32_t *pairs = fs_malloc(cap * sizeof *pairs);
    for (int y = 0; y < g->h; y++)
        for (int x = 0; x < g->w; x++) {
            size_t k = (size_t)y * g->w + x;
            for (int s = 0; s < 2; s++) {
                int32_t q = grid_step(g, x, y, s == 0, s == 1);
                if (q < 0 || label[q] == label[k] || !label[q] || !label[k])
                    continue;
                uint16_t a = label[k] < label[q] ? label[k] : label[q], b = label[k] ^ label[q] ^ a;
                FS_ARRAY_RESERVE(pairs, cap, np + 1, 4096);
                pairs[np++] = (uint32_t)a << 16 | b;
            }
        }
    qsort(pairs, np, sizeof *pairs, cmp_u32);
    out->adjacent = fs_malloc((np + 1) * sizeof *out->adjacent);
    for (size_t i = 0; i < np;) {
        size_t j = i;
        while (j < np && pairs[j] == pairs[i])
            j++;
        if ((int64_t)(j - i) >= min_contact)
            out->adjacent[out->n_adjacent++] =
                (fs_crack_adjacency){(uint16_t)(pairs[i] >> 16), (uint16_t)(pairs[i] & 0xffffu), (int32_t)(j - i)};
        i = j;
    }
    free(pairs);
}

/* Left and right fragments of an edge and its mean width, from its pixels. */
static void edge_sides(const tracer *t, const tedge *e, const uint16_t *label, fs_crack_edge *out)
{
    const grid *g = &t->g;
    uint16_t *left = fs_malloc(((size_t)e->n + 1) * sizeof *left);
    uint16_t *right = fs_malloc(((size_t)e->n + 1) * sizeof *right);
    size_t nl = 0, nr = 0, nw = 0;
    double width = 0.0;
    for (int32_t i = 0; i < e->n; i++) {
        int32_t k = t->pix[e->first + i];
        if (k < 0)
            continue;
        width += 2.0 * t->dist[k] - 1.0;
        nw++;
        const pt *a = &t->pts[e->first + (i >= 2 ? i - 2 : 0)];
        const pt *b = &t->pts[e->first + (i + 2 < e->n ? i + 2 : e->n - 1)];
        double tx = b->x - a->x, ty = b->y - a->y, len = hypot(tx, ty);
        if (!(len > 0.0))
            continue;
        /* Left of the direction of travel with v up is (ty, -tx) in pixel coordinates (y down). */
        double nx = ty / len, ny = -tx / len;
        double off = fmax(2.0, floor(half_width_at(t, k) + 2.0));
        int kx = k % g->w, ky = k / g->w;
        for (int side = 0; side < 2; side++) {
            double sgn = side ? -1.0 : 1.0;
            int32_t q = grid_step(g, kx, ky, (int)lround(sgn * nx * off), (int)lround(sgn * ny * off));
            if (q < 0)
                continue;
            if (side)
                right[nr++] = label[q];
            else
                left[nl++] = label[q];
        }
    }
    out->left = mode_u16(left, nl);
    out->right = mode_u16(right, nr);
    out->width = nw ? width / (double)nw : 0.0;
    free(left);
    free(right);
}

int fs_crackgraph_build(const fs_raster *r, bool wrap_u, bool wrap_v, const fs_crackgraph_params *p,
                        fs_crackgraph *out)
{
    memset(out, 0, sizeof *out);
    const int w = r->width, h = r->height;
    const size_t n = (size_t)w * (size_t)h;
    out->width = w;
    out->height = h;
    out->wrap_u = wrap_u;
    out->wrap_v = wrap_v;
    const grid g = {w, h, wrap_u, wrap_v};

    uint8_t *mask = fs_malloc(n), *material = fs_malloc(n);
    for (size_t k = 0; k < n; k++)
        mask[k] = r->crack[k] >= p->crack_threshold;
    /* Cracks thinner than a pixel leave fragments touching: their boundary, one pixel wide on the
     * side of the larger id, is crack too. */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int32_t k = y * w + x;
            for (int s = 0; s < 2 && r->cell[k]; s++) {
                int32_t q = grid_step(&g, x, y, s == 0, s == 1);
                if (q >= 0 && r->cell[q] && r->cell[q] != r->cell[k])
                    mask[r->cell[k] > r->cell[q] ? k : q] = 1;
            }
        }
    fill_islands(&g, mask, p->min_island);
    size_t n_crack = 0;
    uint16_t *seed = fs_malloc(n * sizeof *seed);
    for (size_t k = 0; k < n; k++) {
        material[k] = !mask[k];
        n_crack += mask[k];
        seed[k] = material[k] ? r->cell[k] : 0;
    }
    float *dist = fs_malloc(n * sizeof *dist);
    int rc = fs_image_distance(material, w, h, wrap_u, wrap_v, dist);
    free(material);
    if (rc < 0) {
        free(mask);
        free(dist);
        free(seed);
        return -1;
    }
    uint16_t *label = fs_malloc(n * sizeof *label);
    grow_labels(&g, seed, label);
    free(seed);
    build_fragments(&g, r->cell, label, p->min_contact, out);

    if (n_crack == 0 || n_crack == n) {
        out->piece_start = fs_calloc(1, sizeof *out->piece_start);
        free(mask);
        free(dist);
        free(label);
        return 0;
    }

    /* Extend the mask past non-wrapping borders by replication, thin, and crop. */
    double max_half = 0.0;
    for (size_t k = 0; k < n; k++)
        if (mask[k])
            max_half = fmax(max_half, dist[k]);
    int pad = (int)ceil(max_half) + 2;
    if (pad > (w > h ? w : h))
        pad = w > h ? w : h;
    const int pu = wrap_u ? 0 : pad, pv = wrap_v ? 0 : pad;
    const grid pg = {w + 2 * pu, h + 2 * pv, wrap_u, wrap_v};
    size_t pn = (size_t)pg.w * (size_t)pg.h;
    uint8_t *fg = fs_malloc(pn);
    for (int y = 0; y < pg.h; y++) {
        int sy = y - pv < 0 ? 0 : y - pv >= h ? h - 1 : y - pv;
        for (int x = 0; x < pg.w; x++) {
            int sx = x - pu < 0 ? 0 : x - pu >= w ? w - 1 : x - pu;
            fg[(size_t)y * pg.w + x] = mask[(size_t)sy * w + sx];
        }
    }
    thin(&pg, fg);
    uint8_t *sk = fs_malloc(n), *outward = fs_calloc(n, 1);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t pk = (size_t)(y + pv) * pg.w + (size_t)(x + pu);
            size_t k = (size_t)y * w + x;
            sk[k] = fg[pk];
            if (!sk[k] || (pu == 0 && pv == 0))
                continue;
            for (int rr = 0; rr < 8; rr++) {
                int qx = x + ring_dx[rr], qy = y + ring_dy[rr];
                bool off_u = !wrap_u && (qx < 0 || qx >= w), off_v = !wrap_v && (qy < 0 || qy >= h);
                if (!off_u && !off_v)
                    continue;
                int32_t q = grid_step(&pg, x + pu, y + pv, ring_dx[rr], ring_dy[rr]);
                if (q >= 0 && fg[q])
                    outward[k] = 1;
            }
        }
    free(fg);
    free(mask);

    tracer t = {.g = g, .sk = sk, .outward = outward, .dist = dist};
    t.count = fs_calloc(n, sizeof *t.count);
    t.cluster = fs_malloc(n * sizeof *t.cluster);
    t.visited = fs_calloc(n, 1);
    t.stub = fs_calloc(n, 1);
    for (size_t k = 0; k < n; k++) {
        t.cluster[k] = -1;
        if (sk[k])
            t.count[k] = popcount8(neighbour_code(&g, sk, (int32_t)k));
    }
    /* A line passing a border pixel that continues outwards branches there (a junction on the
     * border), unless the line itself runs along the border. */
    for (size_t k = 0; k < n; k++) {
        if (!outward[k] || t.count[k] != 2)
            continue;
        bool along = false;
        for (int rr = 0; rr < 8; rr++) {
            int32_t q = grid_step(&g, (int)(k % w), (int)(k / w), ring_dx[rr], ring_dy[rr]);
            along = along || (q >= 0 && sk[q] && outward[q]);
        }
        if (!along) {
            t.stub[k] = 1;
            t.count[k] = 3;
        }
    }
    find_junctions(&t);
    trace_all(&t);
    prune(&t, p);
    count_degrees(&t);

    /* Renumber live nodes; emit live edges. */
    int32_t *renum = fs_malloc(((size_t)t.n_nodes + 1) * sizeof *renum);
    out->node = fs_malloc(((size_t)t.n_nodes + 1) * sizeof *out->node);
    for (int32_t i = 0; i < t.n_nodes; i++) {
        const tnode *nd = &t.node[i];
        renum[i] = -1;
        if (nd->dead || nd->degree == 0)
            continue;
        renum[i] = out->n_nodes;
        double u = nd->x / w, v = 1.0 - nd->y / h;
        if (wrap_u)
            u -= floor(u);
        if (wrap_v)
            v -= floor(v);
        fs_crack_node_kind kind = nd->degree >= 3 ? FS_CRACK_JUNCTION
                                  : nd->kind == FS_CRACK_BORDER ? FS_CRACK_BORDER : FS_CRACK_END;
        out->node[out->n_nodes++] = (fs_crack_node){{u, v}, nd->degree, kind};
    }
    out_pools o = {.g = out};
    out->edge = fs_malloc(((size_t)t.n_edges + 1) * sizeof *out->edge);
    uint8_t *keep = fs_malloc((size_t)t.n_pts + 1);
    int32_t *stack = fs_malloc(4 * ((size_t)t.n_pts + 1) * sizeof *stack);
    double *uv = fs_malloc(2 * ((size_t)t.n_pts + 1) * sizeof *uv);
    for (int32_t i = 0; i < t.n_edges; i++) {
        const tedge *e = &t.edge[i];
        if (e->dead || e->n < 2)
            continue;
        fs_crack_edge *oe = &out->edge[out->n_edges++];
        oe->node[0] = e->node[0] >= 0 ? renum[e->node[0]] : -1;
        oe->node[1] = e->node[1] >= 0 ? renum[e->node[1]] : -1;
        oe->length = path_length(&t, e);
        edge_sides(&t, e, label, oe);
        const pt *path = t.pts + e->first;
        simplify(path, e->n, p->simplify, keep, stack);
        int32_t m = 0;
        for (int32_t k = 0; k < e->n; k++) {
            if (!keep[k])
                continue;
            uv[2 * m] = path[k].x / w;
            uv[2 * m + 1] = 1.0 - path[k].y / h;
            m++;
        }
        oe->first_piece = out->n_pieces;
        emit_pieces(&o, uv, m, wrap_u, wrap_v);
        oe->n_pieces = out->n_pieces - oe->first_piece;
    }
    out_piece_start(&o);
    out->n_pieces--; /* the sentinel offset is not a piece */

    free(keep);
    free(stack);
    free(uv);
    free(renum);
    free(t.count);
    free(t.cluster);
    free(t.visited);
    free(t.stub);
    free(t.node);
    free(t.edge);
    free(t.pts);
    free(t.pix);
    free(sk);
    free(outward);
    free(dist);
    free(label);
    return 0;
}

void fs_crackgraph_free(fs_crackgraph *g)
{
    if (!g)
        return;
    free(g->node);
    free(g->edge);
    free(g->piece_start);
    free(g->point);
    free(g->fragment);
    free(g->adjacent);
    memset(g, 0, sizeof *g);
}
