/* Behaviour tests of wedge fracture by element splitting (SPEC §9), measured on the final mesh's crack graph and fragments. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/error.h"
#include "check.h"
#include "setup.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "io/preset.h"
#include "model/wedge/internal.h"

#define DEG (180.0 / 3.14159265358979323846)

/* ---- running the model ---- */

/* Wall-clock seconds, for the timings the tests print. */
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The drying-mud preset (presets/mud.ini: periodic plane, top shrinking twice as fast as the bottom,
 * splitting, no Griffith) on a smaller tile with the given element count, thickness and seed. The
 * minimum size is above every element, so nothing is subdivided and the mesh only changes by cuts. */
static fs_config mud_config(double size, int32_t elements, double thickness, uint64_t seed)
{
    fs_config c = fs_config_default();
    char path[1024];
    snprintf(path, sizeof path, "%s/presets/mud.ini", FS_SRCDIR);
    int rc = fs_preset_load(path, &c);
    CHECK_MSG(rc == 0, "%s: %s", path, fs_error_message());
    c.preset.seed = seed;
    c.domain.width = c.domain.height = size;
    c.mesh.elements = elements;
    c.mesh.min_size = 1e3;
    c.material.thickness = thickness;
    return c;
}

/* A bark-like layer on a growing trunk: a cylinder periodic around (always) and along the axis, whose
 * radial growth stretches the layer only around (SPEC §9, growth fields); no shrinkage. At the end
 * the hoop strain is rate t / R = 0.005, and the hoop stress of an uncracked bonded layer,
 * E eps / (1 - nu^2), about 2.7 thresholds, while the axial stress, nu times that, stays below it. */
static fs_config trunk_config(int32_t elements, uint64_t seed)
{
    fs_config c = fs_config_default();
    c.preset.model = FS_MODEL_WEDGE;
    c.preset.seed = seed;
    c.domain.type = FS_DOMAIN_CYLINDER;
    c.domain.radius = 1.0;
    c.domain.height = 4.0;
    c.domain.periodic_y = true;
    c.mesh.elements = elements;
    c.mesh.min_size = 1e3;
    c.material.young = 100.0;
    c.material.poisson = 0.3;
    c.material.threshold = 200.0;
    c.material.jitter = 0.1;
    c.material.thickness = 0.25;
    c.material.thickness_final = -1.0;
    c.material.toughness = 0.0;
    c.growth.type = FS_GROWTH_CYLINDER;
    c.growth.rate = 0.005;
    c.fracture.method = FS_FRACTURE_SPLIT;
    c.fracture.griffith = false;
    c.time.end = 1.0;
    c.time.min_step = 1e-3;
    c.solver.method = FS_SOLVER_CHOLMOD;
    return c;
}

/* Samples and meshes cfg's domain as fs_sim_run does for the wedge model (two triangles a point). */
static int make_mesh(const fs_config *cfg, fs_mesh *m)
{
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = cfg->mesh.elements / 2;
    sp.iterations = cfg->mesh.relax_iterations;
    sp.radius_jitter = cfg->mesh.radius_jitter;
    sp.seed = cfg->preset.seed;
    fs_points pts = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0)
        return -1;
    int rc = fs_delaunay(&d, &pts, m);
    fs_points_free(&pts);
    return rc;
}

/* The mean edge length of a mesh (cm): the element size the crack graph is measured in. */
static double mean_edge(const fs_mesh *m)
{
    double sum = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int i = 0; i < 3; i++) {
            double a[3], b[3];
            fs_mesh_corner(m, t, i, a);
            fs_mesh_corner(m, t, (i + 1) % 3, b);
            sum += hypot(b[0] - a[0], b[1] - a[1]);
        }
    return m->n_tris ? sum / (3.0 * m->n_tris) : 0.0;
}

/* A finished simulation: the configuration, the cracked mesh, the mean edge length before any cut
 * (the element size the crack graph is measured in), and the model's own fragment count
 * (fs_wedge_fragments), which count_fragments must reproduce. */
typedef struct {
    fs_config cfg;
    fs_mesh mesh;
    double h0;
    int32_t model_fragments;
    bool ok;
} run;

/* Meshes cfg's domain and simulates it to cfg->time.end, printing what it took. The failures are
 * counted; r->ok tells whether r->mesh holds a result. */
static void simulate(const fs_config *cfg, const char *what, run *r)
{
    memset(r, 0, sizeof *r);
    r->cfg = *cfg;
    double t0 = now();
    int rc = make_mesh(cfg, &r->mesh);
    CHECK_MSG(rc == 0, "%s: mesh: %s", what, fs_error_message());
    if (rc < 0)
        return;
    r->h0 = mean_edge(&r->mesh);
    fs_wedge_model w;
    rc = fs_wedge_init(&w, &r->mesh, SETUP(cfg));
    CHECK_MSG(rc == 0, "%s: init: %s", what, fs_error_message());
    if (rc < 0)
        return;
    rc = fs_wedge_simulate(&w, cfg->time.end);
    CHECK_MSG(rc == 0, "%s: simulate: %s", what, fs_error_message());
    printf("  %s: %d elements (edge %.3f cm), %lld splits, %.1f s\n", what, (int)w.n_elems, r->h0,
           (long long)w.fractures, now() - t0);
    int32_t *labels = malloc(sizeof *labels * (size_t)(w.n_elems + 1));
    r->model_fragments = fs_wedge_fragments(&w, labels);
    free(labels);
    fs_wedge_free(&w);
    r->ok = rc == 0;
}

/* Mud runs, kept so that tests needing the same simulation share it (freed by free_runs). */
#define MAX_RUNS 16
static run mud_runs[MAX_RUNS];
static int n_mud_runs;

/* The mud simulation of mud_config(size, elements, thickness, seed), run on first use. */
static const run *mud_run(double size, int32_t elements, double thickness, uint64_t seed)
{
    for (int k = 0; k < n_mud_runs; k++) {
        const fs_config *c = &mud_runs[k].cfg;
        if (c->domain.width == size && c->mesh.elements == elements && c->material.thickness == thickness &&
            c->preset.seed == seed)
            return &mud_runs[k];
    }
    FS_ASSERT(n_mud_runs < MAX_RUNS);
    fs_config cfg = mud_config(size, elements, thickness, seed);
    char what[128];
    snprintf(what, sizeof what, "mud %g x %g cm, %d elements, %g cm thick, seed %d", size, size, (int)elements,
             thickness, (int)seed);
    simulate(&cfg, what, &mud_runs[n_mud_runs]);
    return &mud_runs[n_mud_runs++];
}

static void free_runs(void)
{
    for (int k = 0; k < n_mud_runs; k++)
        fs_mesh_free(&mud_runs[k].mesh);
    n_mud_runs = 0;
}

/* ---- fragments ---- */

static int32_t find_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Fragments of a cracked mesh: connected components of triangles sharing a node (a crack duplicates
 * its nodes, so the pieces on either side share none). Returns the count. */
static int32_t count_fragments(const fs_mesh *m)
{
    int32_t *parent = malloc(sizeof *parent * (size_t)m->n_nodes);
    for (int32_t i = 0; i < m->n_nodes; i++)
        parent[i] = i;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int c = 1; c < 3; c++) {
            int32_t a = find_root(parent, m->tri[3 * t]), b = find_root(parent, m->tri[3 * t + c]);
            if (a != b)
                parent[a] = b;
        }
    int32_t count = 0;
    uint8_t *seen = calloc((size_t)m->n_nodes, 1);
    for (int32_t t = 0; t < m->n_tris; t++) {
        int32_t r = find_root(parent, m->tri[3 * t]);
        count += !seen[r];
        seen[r] = 1;
    }
    free(seen);
    free(parent);
    return count;
}

/* The fragments of a run, checked against the model's count. */
static int32_t run_fragments(const run *r)
{
    int32_t n = count_fragments(&r->mesh);
    CHECK_MSG(n == r->model_fragments, "%d fragments in the mesh, %d by fs_wedge_fragments", (int)n,
              (int)r->model_fragments);
    return n;
}

/* ---- the crack graph ---- */

/* design: a crack of the split mesh is a pair of boundary half-edges (its two walls) on distinct
 * nodes at the same position (node duplication copies the position). Grouping the nodes by position
 * gives one graph vertex per crack point and one segment per crack edge; vertices where three or
 * more segments meet are junctions, those with one are crack tips. Displacements along the graph use
 * the periodic shortest difference (fs_domain_delta), so cracks run across the seams. */
typedef struct {
    fs_domain domain;
    int32_t n_vertices;
    double *pos;        /* 3 per vertex, domain coordinates */
    int32_t n_segments;
    int32_t *seg;       /* 2 per segment: its end vertices */
    int32_t *start;     /* n_vertices + 1: segments at each vertex (CSR into at) */
    int32_t *at;
} crack_graph;

static void graph_free(crack_graph *g)
{
    free(g->pos);
    free(g->seg);
    free(g->start);
    free(g->at);
    memset(g, 0, sizeof *g);
}

/* Fills the vertex-to-segment incidence of g from its segments. */
static void graph_index(crack_graph *g)
{
    g->start = calloc((size_t)g->n_vertices + 1, sizeof *g->start);
    g->at = malloc(sizeof *g->at * (size_t)(2 * g->n_segments + 1));
    for (int32_t s = 0; s < 2 * g->n_segments; s++)
        g->start[g->seg[s] + 1]++;
    for (int32_t v = 0; v < g->n_vertices; v++)
        g->start[v + 1] += g->start[v];
    int32_t *fill = malloc(sizeof *fill * (size_t)(g->n_vertices + 1));
    memcpy(fill, g->start, sizeof *fill * (size_t)g->n_vertices);
    for (int32_t s = 0; s < 2 * g->n_segments; s++)
        g->at[fill[g->seg[s]]++] = s / 2;
    free(fill);
}

static int32_t degree(const crack_graph *g, int32_t v)
{
    return g->start[v + 1] - g->start[v];
}

static const double *sort_pos;

static int cmp_node_pos(const void *a, const void *b)
{
    const double *p = sort_pos + 3 * (size_t)*(const int32_t *)a, *q = sort_pos + 3 * (size_t)*(const int32_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int cmp_pair(const void *a, const void *b)
{
    const int32_t *p = a, *q = b;
    return p[0] != q[0] ? (p[0] < q[0] ? -1 : 1) : p[1] != q[1] ? (p[1] < q[1] ? -1 : 1) : 0;
}

/* The crack graph of a split mesh (see the design note). The two walls of a crack need not have the
 * same vertices: a crack that ends on an earlier one (a T-junction) cuts the wall on its own side
 * only, so the facing wall runs straight past the junction. Walls are therefore first cut at every
 * crack vertex lying on them, after which each crack segment has exactly two walls; *unpaired
 * receives the number of segments that still do not. */
static void graph_of_mesh(const fs_mesh *m, crack_graph *g, int32_t *unpaired)
{
    memset(g, 0, sizeof *g);
    g->domain = m->domain;
    int32_t n = m->n_nodes;
    double *wrapped = malloc(sizeof *wrapped * 3 * (size_t)n);
    int32_t *order = malloc(sizeof *order * (size_t)n), *group = malloc(sizeof *group * (size_t)n);
    for (int32_t i = 0; i < n; i++) {
        memcpy(wrapped + 3 * i, m->pos + 3 * i, 3 * sizeof *wrapped);
        fs_domain_wrap(&m->domain, wrapped + 3 * i);
        order[i] = i;
    }
    sort_pos = wrapped;
    qsort(order, (size_t)n, sizeof *order, cmp_node_pos);
    int32_t groups = 0;
    for (int32_t q = 0; q < n; q++) {
        if (q > 0 && cmp_node_pos(order + q - 1, order + q) != 0)
            groups++;
        group[order[q]] = groups;
    }
    groups += n > 0;
    /* vertices: the groups on a wall, numbered in group order */
    int32_t *vertex = malloc(sizeof *vertex * (size_t)(groups + 1));
    for (int32_t k = 0; k < groups; k++)
        vertex[k] = -1;
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] < 0) {
            vertex[group[m->tri[h]]] = 0;
            vertex[group[m->tri[3 * (h / 3) + (h % 3 + 1) % 3]]] = 0;
        }
    g->pos = malloc(sizeof *g->pos * 3 * (size_t)(groups + 1));
    for (int32_t q = 0; q < n; q++) {
        int32_t k = group[order[q]];
        if (vertex[k] == 0) {
            memcpy(g->pos + 3 * g->n_vertices, wrapped + 3 * order[q], 3 * sizeof *g->pos);
            vertex[k] = ++g->n_vertices; /* 1-based while numbering, so 0 still means "unnumbered" */
        }
    }
    for (int32_t k = 0; k < groups; k++)
        vertex[k] -= vertex[k] > 0;
    /* walls as vertex pairs, cut at the vertices lying on them; then smaller vertex first */
    int32_t n_walls = 0, cap = 3 * m->n_tris + 16;
    int32_t *wall = malloc(sizeof *wall * 2 * (size_t)cap);
    double *cut = malloc(sizeof *cut * 2 * (size_t)(g->n_vertices + 1));
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        int32_t a = vertex[group[m->tri[h]]], b = vertex[group[m->tri[3 * (h / 3) + (h % 3 + 1) % 3]]];
        double d[3];
        fs_domain_delta(&m->domain, g->pos + 3 * a, g->pos + 3 * b, d);
        double dd = d[0] * d[0] + d[1] * d[1];
        int32_t n_cut = 0;
        for (int32_t c = 0; c < g->n_vertices; c++) {
            double e[3];
            fs_domain_delta(&m->domain, g->pos + 3 * a, g->pos + 3 * c, e);
            double t = (e[0] * d[0] + e[1] * d[1]) / dd;
            if (c == a || c == b || !(t > 1e-9 && t < 1.0 - 1e-9))
                continue;
            if (hypot(e[0] - t * d[0], e[1] - t * d[1]) <= 1e-9 * sqrt(dd)) {
                cut[2 * n_cut] = t;
                cut[2 * n_cut + 1] = c;
                n_cut++;
            }
        }
        qsort(cut, (size_t)n_cut, 2 * sizeof *cut, cmp_double);
        if (n_walls + n_cut + 1 > cap) {
            cap = 2 * (n_walls + n_cut + 1);
            wall = realloc(wall, sizeof *wall * 2 * (size_t)cap);
        }
        int32_t from = a;
        for (int32_t k = 0; k <= n_cut; k++) {
            int32_t to = k < n_cut ? (int32_t)cut[2 * k + 1] : b;
            wall[2 * n_walls] = from < to ? from : to;
            wall[2 * n_walls + 1] = from < to ? to : from;
            n_walls++;
            from = to;
        }
    }
    qsort(wall, (size_t)n_walls, 2 * sizeof *wall, cmp_pair);
    g->seg = malloc(sizeof *g->seg * 2 * (size_t)(n_walls + 1));
    *unpaired = 0;
    for (int32_t k = 0; k < n_walls;) {
        int32_t j = k;
        while (j < n_walls && cmp_pair(wall + 2 * j, wall + 2 * k) == 0)
            j++;
        *unpaired += j - k != 2;
        g->seg[2 * g->n_segments] = wall[2 * k];
        g->seg[2 * g->n_segments + 1] = wall[2 * k + 1];
        g->n_segments++;
        k = j;
    }
    graph_index(g);
    free(cut);
    free(vertex);
    free(wall);
    free(group);
    free(order);
    free(wrapped);
}

/* The Voronoi crack pattern of a periodic Delaunay mesh: a vertex at every circumcentre, a segment
 * across every edge (the non-physical baseline of the voronoi model). */
static int graph_of_voronoi(const fs_mesh *m, crack_graph *g)
{
    memset(g, 0, sizeof *g);
    g->domain = m->domain;
    fs_voronoi v;
    if (fs_voronoi_build(m, &v) < 0)
        return -1;
    g->n_vertices = m->n_tris;
    g->pos = malloc(sizeof *g->pos * 3 * (size_t)m->n_tris);
    for (int32_t t = 0; t < m->n_tris; t++) {
        memcpy(g->pos + 3 * t, v.circumcenter + 3 * t, 3 * sizeof *g->pos);
        fs_domain_wrap(&m->domain, g->pos + 3 * t);
    }
    g->seg = malloc(sizeof *g->seg * 2 * (size_t)(m->n_edges + 1));
    for (int32_t e = 0; e < m->n_edges; e++)
        if (m->edge_tri[2 * e] >= 0 && m->edge_tri[2 * e + 1] >= 0) {
            g->seg[2 * g->n_segments] = m->edge_tri[2 * e];
            g->seg[2 * g->n_segments + 1] = m->edge_tri[2 * e + 1];
            g->n_segments++;
        }
    fs_voronoi_free(&v);
    graph_index(g);
    return 0;
}

static int32_t other_end(const crack_graph *g, int32_t s, int32_t v)
{
    return g->seg[2 * s] == v ? g->seg[2 * s + 1] : g->seg[2 * s];
}

/* The direction (unit, in the unwrapped plane) of the branch leaving vertex v through segment s: the
 * chord from v to the point at arc length reach along the branch, or to the branch's far end (a
 * junction or a tip) if it is shorter. */
static void branch_direction(const crack_graph *g, int32_t v, int32_t s, double reach, double dir[2])
{
    double p[2] = {0.0, 0.0}, arc = 0.0;
    int32_t cur = v;
    for (;;) {
        int32_t next = other_end(g, s, cur);
        double d[3];
        fs_domain_delta(&g->domain, g->pos + 3 * cur, g->pos + 3 * next, d);
        double len = hypot(d[0], d[1]);
        if (arc + len >= reach && len > 0.0) {
            double f = (reach - arc) / len;
            p[0] += f * d[0];
            p[1] += f * d[1];
            break;
        }
        p[0] += d[0];
        p[1] += d[1];
        arc += len;
        cur = next;
        if (degree(g, cur) != 2 || cur == v)
            break;
        s = g->at[g->start[cur]] == s ? g->at[g->start[cur] + 1] : g->at[g->start[cur]];
    }
    double len = hypot(p[0], p[1]);
    dir[0] = len > 0.0 ? p[0] / len : 1.0;
    dir[1] = len > 0.0 ? p[1] / len : 0.0;
}

static double median(double *v, int32_t n)
{
    if (n == 0)
        return NAN;
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Junction angle statistics of a crack graph. At each three-branch junction the three angles between
 * consecutive branches (degrees, summing to 360) are sorted, s1 <= s2 <= s3, and compared with the
 * two templates: a T-junction (90, 90, 180), where a crack ends on a straight earlier one at a right
 * angle, and a Y-junction (120, 120, 120), where three cracks meet symmetrically as in a Voronoi
 * pattern. Each template's misfit is the mean absolute difference of the three angles. */
typedef struct {
    int32_t junctions;      /* three-branch junctions */
    int32_t crossings;      /* junctions of four or more branches (not measured) */
    int32_t tips;           /* crack ends (one branch) */
    double median_t_misfit; /* median misfit to the T template (degrees): 0 for perfect T's, 40 for Y's */
    double t_fraction;      /* fraction of junctions closer to the T template than to the Y one */
    double right_fraction;  /* fraction of the junction angles s1, s2 within 90 +- 20 degrees */
} junction_stats;

static junction_stats junction_angles(const crack_graph *g, double reach)
{
    junction_stats st = {0};
    double *misfit = malloc(sizeof *misfit * (size_t)(g->n_vertices + 1));
    int32_t closer_t = 0, right = 0;
    for (int32_t v = 0; v < g->n_vertices; v++) {
        int32_t deg = degree(g, v);
        st.tips += deg == 1;
        st.crossings += deg >= 4;
        if (deg != 3)
            continue;
        double th[3], gap[3];
        for (int k = 0; k < 3; k++) {
            double dir[2];
            branch_direction(g, v, g->at[g->start[v] + k], reach, dir);
            th[k] = atan2(dir[1], dir[0]) * DEG;
        }
        qsort(th, 3, sizeof *th, cmp_double);
        gap[0] = th[1] - th[0];
        gap[1] = th[2] - th[1];
        gap[2] = 360.0 - (th[2] - th[0]);
        qsort(gap, 3, sizeof *gap, cmp_double);
        double mt = (fabs(gap[0] - 90.0) + fabs(gap[1] - 90.0) + fabs(gap[2] - 180.0)) / 3.0;
        double my = (fabs(gap[0] - 120.0) + fabs(gap[1] - 120.0) + fabs(gap[2] - 120.0)) / 3.0;
        misfit[st.junctions++] = mt;
        closer_t += mt < my;
        right += (fabs(gap[0] - 90.0) <= 20.0) + (fabs(gap[1] - 90.0) <= 20.0);
    }
    st.median_t_misfit = median(misfit, st.junctions);
    st.t_fraction = st.junctions ? (double)closer_t / st.junctions : NAN;
    st.right_fraction = st.junctions ? (double)right / (2.0 * st.junctions) : NAN;
    free(misfit);
    return st;
}

/* Fraction of the crack length running within max_angle degrees of the domain's y axis (the trunk's
 * axis on a cylinder). The graph is cut into pieces of about piece cm of arc length along its branches
 * (between junctions and tips), each weighted by its arc length and oriented by its chord, so the
 * zig-zag of a crack through the elements does not count as its direction. *total receives the crack
 * length (cm). */
static double axial_fraction(const crack_graph *g, double piece, double max_angle, double *total)
{
    uint8_t *done = calloc((size_t)g->n_segments + 1, 1);
    double along = 0.0, all = 0.0;
    for (int32_t s0 = 0; s0 < g->n_segments; s0++) {
        if (done[s0])
            continue;
        /* walk back to a branch end (or once around a closed loop), then forth along the branch */
        int32_t v = g->seg[2 * s0], s = s0;
        while (degree(g, v) == 2) {
            int32_t t = g->at[g->start[v]] == s ? g->at[g->start[v] + 1] : g->at[g->start[v]];
            if (t == s0)
                break;
            s = t;
            v = other_end(g, s, v);
        }
        double chord[2] = {0.0, 0.0}, arc = 0.0;
        for (;;) {
            done[s] = 1;
            int32_t next = other_end(g, s, v);
            double d[3];
            fs_domain_delta(&g->domain, g->pos + 3 * v, g->pos + 3 * next, d);
            chord[0] += d[0];
            chord[1] += d[1];
            arc += hypot(d[0], d[1]);
            v = next;
            int32_t t = degree(g, v) == 2 ? (g->at[g->start[v]] == s ? g->at[g->start[v] + 1] : g->at[g->start[v]]) : -1;
            bool end = t < 0 || done[t];
            if (arc >= piece || end) {
                double angle = atan2(fabs(chord[0]), fabs(chord[1])) * DEG;
                all += arc;
                along += angle <= max_angle ? arc : 0.0;
                chord[0] = chord[1] = arc = 0.0;
            }
            if (end)
                break;
            s = t;
        }
    }
    free(done);
    *total = all;
    return all > 0.0 ? along / all : NAN;
}


/* ---- the tests ---- */

/* The crack graph of a run, checked: every crack segment has its two walls. */
static void run_graph(const run *r, crack_graph *g)
{
    int32_t unpaired = 0;
    graph_of_mesh(&r->mesh, g, &unpaired);
    CHECK_MSG(unpaired == 0, "%d crack segments without exactly two walls", (int)unpaired);
}

static void print_junctions(const char *what, const junction_stats *s)
{
    printf("  %s: %d junctions (%d of 4+ branches, %d tips), median misfit to (90, 90, 180) %.1f deg, "
           "closer to T than to Y %.0f %%, angles within 90 +- 20 deg %.0f %%\n",
           what, (int)s->junctions, (int)s->crossings, (int)s->tips, s->median_t_misfit, 100.0 * s->t_fraction,
           100.0 * s->right_fraction);
}

/* The right-angle criterion: enough junctions, most of them closer to a T than to a Y, a median misfit
 * to the T well below the 40 degrees of a perfect Y, and most angles next to the through-crack near
 * 90 degrees. */
static bool mostly_right_angles(const junction_stats *s)
{
    return s->junctions >= 20 && s->t_fraction > 0.5 && s->median_t_misfit < 20.0 && s->right_fraction > 0.5;
}

/* Branch directions are taken two element sizes away from a junction. */
#define REACH 2.0

/* Mud cracks meet mostly at right angles (SPEC §9, thesis Fig. 5.28/5.30): a crack grows until it meets
 * an earlier one, and it meets it at a right angle because the stress across the earlier crack is
 * relieved, so it turns to run normal to it (T-junctions). The Voronoi pattern of the voronoi model,
 * whose cells meet three by three at about 120 degrees, must fail the same criterion. */
static void test_mud_right_angles(void)
{
    const run *r = mud_run(4.0, 2000, 0.2, 1);
    if (!r->ok)
        return;
    crack_graph g;
    run_graph(r, &g);
    junction_stats mud = junction_angles(&g, REACH * r->h0);
    print_junctions("mud", &mud);
    CHECK_MSG(mostly_right_angles(&mud), "mud junctions: median misfit %.1f deg, %.0f %% T, %.0f %% right angles",
              mud.median_t_misfit, 100.0 * mud.t_fraction, 100.0 * mud.right_fraction);
    graph_free(&g);

    /* the control: Voronoi cells of evenly spread points, about as large as the mud fragments */
    fs_config cfg = mud_config(4.0, 2 * 64, 0.2, 1);
    fs_mesh m = {0};
    CHECK(make_mesh(&cfg, &m) == 0);
    CHECK(graph_of_voronoi(&m, &g) == 0);
    junction_stats voronoi = junction_angles(&g, REACH * r->h0);
    print_junctions("voronoi (64 cells)", &voronoi);
    CHECK_MSG(voronoi.junctions == 128, "%d Voronoi junctions", (int)voronoi.junctions);
    CHECK_MSG(!mostly_right_angles(&voronoi), "the Voronoi pattern passes as right-angled: median misfit %.1f deg, "
              "%.0f %% T, %.0f %% right angles", voronoi.median_t_misfit, 100.0 * voronoi.t_fraction,
              100.0 * voronoi.right_fraction);
    graph_free(&g);
    fs_mesh_free(&m);
}

/* Cracks within this angle of the axis count as axial. */
#define AXIAL_DEGREES 30.0

/* Growth around a trunk opens cracks along its axis (SPEC §9, thesis Fig. 5.33): radial growth
 * stretches the layer only around, so the largest principal stress is the hoop stress and cracks run
 * normal to it. Most of the crack length must lie within 30 degrees of the axis; the isotropic mud
 * pattern, measured the same way, must not. */
static void test_trunk_axial_cracks(void)
{
    fs_config cfg = trunk_config(1500, 1);
    run r;
    simulate(&cfg, "trunk, radius 1 cm, 4 cm long, 1500 elements, seed 1", &r);
    if (r.ok) {
        crack_graph g;
        run_graph(&r, &g);
        double total = 0.0, axial = axial_fraction(&g, REACH * r.h0, AXIAL_DEGREES, &total);
        printf("  trunk: %.1f cm of cracks, %.1f %% within %g deg of the axis\n", total, 100.0 * axial,
               AXIAL_DEGREES);
        CHECK_MSG(total > 4.0 * cfg.domain.height, "only %.1f cm of cracks", total);
        CHECK_MSG(axial >= 0.75, "%.1f %% of the crack length within %g deg of the axis", 100.0 * axial,
                  AXIAL_DEGREES);
        graph_free(&g);
    }
    fs_mesh_free(&r.mesh);

    const run *mud = mud_run(4.0, 2000, 0.2, 1);
    if (mud->ok) {
        crack_graph g;
        run_graph(mud, &g);
        double total = 0.0, axial = axial_fraction(&g, REACH * mud->h0, AXIAL_DEGREES, &total);
        printf("  mud (control): %.1f cm of cracks, %.1f %% within %g deg of y\n", total, 100.0 * axial,
               AXIAL_DEGREES);
        CHECK_MSG(axial < 0.75, "the isotropic mud pattern passes as axial: %.1f %%", 100.0 * axial);
        graph_free(&g);
    }
}

/* The thickness criterion: clearly more fragments. */
static bool clearly_more(int32_t many, int32_t few)
{
    return many >= 1.5 * few;
}

/* Thinner layers crack into smaller pieces (SPEC §9, thesis Fig. 5.29): the stress a crack relieves
 * reaches a few thicknesses from it, so the spacing of the cracks is roughly proportional to the
 * thickness and halving it should give about four times as many fragments; at least 1.5 times. */
static void test_thinner_more_fragments(void)
{
    const run *thick = mud_run(4.0, 2000, 0.4, 1), *thin = mud_run(4.0, 2000, 0.2, 1);
    if (!thick->ok || !thin->ok)
        return;
    int32_t n_thick = run_fragments(thick), n_thin = run_fragments(thin);
    printf("  fragments: %d at 0.4 cm, %d at 0.2 cm (ratio %.2f, spacing ratio %.2f)\n", (int)n_thick,
           (int)n_thin, (double)n_thin / n_thick, sqrt((double)n_thin / n_thick));
    CHECK_MSG(n_thick >= 4, "%d fragments at 0.4 cm", (int)n_thick);
    CHECK_MSG(clearly_more(n_thin, n_thick), "%d fragments at 0.2 cm, %d at 0.4 cm", (int)n_thin, (int)n_thick);
    CHECK(!clearly_more(n_thick, n_thin));
}

/* The refinement criterion: counts within 25 % of the coarse one. */
static bool similar(int32_t coarse, int32_t fine)
{
    return fabs((double)fine - coarse) <= 0.25 * coarse;
}

/* FEM patterns keep their crack density when the mesh is refined (SPEC §9; the mass-spring model does
 * not, thesis Fig. 4.9): four times the elements (half the element size) keep the number of fragments,
 * summed over three seeds, within 25 %. The criterion must reject the change a halved thickness
 * makes. */
static void test_refinement_keeps_fragments(void)
{
    int32_t coarse = 0, fine = 0;
    for (uint64_t seed = 1; seed <= 3; seed++) {
        const run *a = mud_run(4.0, 1000, 0.3, seed), *b = mud_run(4.0, 4000, 0.3, seed);
        if (!a->ok || !b->ok)
            return;
        int32_t na = run_fragments(a), nb = run_fragments(b);
        printf("  seed %d: %d fragments with 1000 elements, %d with 4000\n", (int)seed, (int)na, (int)nb);
        coarse += na;
        fine += nb;
    }
    printf("  fragments over 3 seeds: %d coarse, %d fine (%+.0f %%)\n", (int)coarse, (int)fine,
           100.0 * ((double)fine / coarse - 1.0));
    CHECK_MSG(coarse >= 3 * 15, "%d coarse fragments over 3 seeds: too few to compare", (int)coarse);
    CHECK_MSG(similar(coarse, fine), "%d fragments with 1000 elements, %d with 4000", (int)coarse, (int)fine);
    const run *thick = mud_run(4.0, 2000, 0.4, 1), *thin = mud_run(4.0, 2000, 0.2, 1);
    if (thick->ok && thin->ok)
        CHECK(!similar(run_fragments(thick), run_fragments(thin)));
}

int main(void)
{
    RUN(test_mud_right_angles);
    RUN(test_trunk_axial_cracks);
    RUN(test_thinner_more_fragments);
    RUN(test_refinement_keeps_fragments);
    free_runs();
    return check_finish();
}
