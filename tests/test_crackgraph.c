/* Tests of the crack graph: topology of hand-drawn cracks, seams, and the graph of real voronoi maps. */
#include "render/crackgraph.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "geom/domain.h"
#include "io/preset.h"
#include "sim/sim.h"

/* ---- hand-drawn rasters ---- */

static void blank_raster(fs_raster *r, int w, int h)
{
    size_t n = (size_t)w * (size_t)h;
    r->width = w;
    r->height = h;
    r->height_cm = fs_calloc(n, sizeof *r->height_cm);
    r->crack = fs_calloc(n, sizeof *r->crack);
    r->shade = fs_calloc(n, sizeof *r->shade);
    r->cell = fs_calloc(n, sizeof *r->cell);
}

/* Marks pixels within half_width of the segment (x0, y0)-(x1, y1) (pixel units, y down) as crack. */
static void draw_band(fs_raster *r, double x0, double y0, double x1, double y1, double half_width)
{
    double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy;
    for (int j = 0; j < r->height; j++)
        for (int i = 0; i < r->width; i++) {
            double px = i + 0.5 - x0, py = j + 0.5 - y0;
            double t = (px * dx + py * dy) / len2;
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            if (hypot(px - t * dx, py - t * dy) <= half_width)
                r->crack[(size_t)j * r->width + i] = 1.0f;
        }
}

/* Gives each 4-connected region of non-crack pixels the id of fn(centre of its first pixel). */
static void label_cells(fs_raster *r, uint16_t (*fn)(double x, double y, int w, int h))
{
    for (int j = 0; j < r->height; j++)
        for (int i = 0; i < r->width; i++) {
            size_t k = (size_t)j * r->width + i;
            r->cell[k] = r->crack[k] >= 0.5f ? 0 : fn(i + 0.5, j + 0.5, r->width, r->height);
        }
}

static const fs_crack_adjacency *find_pair(const fs_crackgraph *g, int a, int b)
{
    for (int32_t k = 0; k < g->n_adjacent; k++)
        if ((g->adjacent[k].a == a && g->adjacent[k].b == b) || (g->adjacent[k].a == b && g->adjacent[k].b == a))
            return &g->adjacent[k];
    return NULL;
}

static uint16_t t_cells(double x, double y, int w, int h)
{
    (void)h;
    return y < 30 ? 1 : x < w / 2.0 ? 2 : 3;
}

/* A T: a horizontal crack across a bounded 80 x 60 map with a vertical one from its middle down to
 * the bottom. One junction of degree 3 where they meet, three ends on the border, the three
 * fragments pairwise adjacent, and the branches' sides seen correctly. */
static void test_t_junction(void)
{
    fs_raster r = {0};
    blank_raster(&r, 80, 60);
    draw_band(&r, -5, 30, 85, 30, 2.0);
    draw_band(&r, 40, 30, 40, 65, 2.0);
    label_cells(&r, t_cells);
    fs_crackgraph_params p = fs_crackgraph_params_default();
    fs_crackgraph g;
    CHECK(fs_crackgraph_build(&r, false, false, &p, &g) == 0);
    int junctions = 0, borders = 0, ends = 0;
    for (int32_t i = 0; i < g.n_nodes; i++) {
        const fs_crack_node *n = &g.node[i];
        if (n->kind == FS_CRACK_JUNCTION) {
            junctions++;
            CHECK(n->degree == 3);
            CHECK_NEAR(n->uv[0], 40.0 / 80, 2.5 / 80);
            CHECK_NEAR(n->uv[1], 1.0 - 30.0 / 60, 2.5 / 60);
        } else if (n->kind == FS_CRACK_BORDER) {
            borders++;
            CHECK(n->degree == 1);
            bool on_border = n->uv[0] == 0.0 || n->uv[0] == 1.0 || n->uv[1] == 0.0 || n->uv[1] == 1.0;
            CHECK_MSG(on_border, "border node at (%g, %g)", n->uv[0], n->uv[1]);
        } else {
            ends++;
        }
    }
    CHECK_MSG(junctions == 1 && borders == 3 && ends == 0, "%d junctions, %d border ends, %d ends", junctions,
              borders, ends);
    CHECK(g.n_edges == 3);
    CHECK(g.n_fragments == 3);
    CHECK(find_pair(&g, 1, 2) && find_pair(&g, 1, 3) && find_pair(&g, 2, 3));
    CHECK(g.n_adjacent == 3);
    for (int32_t e = 0; e < g.n_edges; e++) {
        const fs_crack_edge *ed = &g.edge[e];
        CHECK(ed->n_pieces == 1);
        CHECK_NEAR(ed->width, 4.0, 1.01);
        /* Straight bands simplify to their two ends. */
        CHECK(g.piece_start[ed->first_piece + 1] - g.piece_start[ed->first_piece] <= 3);
        const double *a = g.point + 2 * g.piece_start[ed->first_piece];
        const double *b = g.point + 2 * (g.piece_start[ed->first_piece + 1] - 1);
        /* Left is the side to the left when walking from a to b with v up. */
        double dir_u = b[0] - a[0], dir_v = b[1] - a[1];
        if (fabs(dir_u) > fabs(dir_v)) { /* a half of the horizontal crack: 1 above, 2 or 3 below */
            int below = (a[0] + b[0]) / 2 < 0.5 ? 2 : 3;
            CHECK(ed->left == (dir_u > 0 ? 1 : below) && ed->right == (dir_u > 0 ? below : 1));
        } else { /* the vertical crack: 2 at small u, 3 at large u */
            CHECK(ed->left == (dir_v > 0 ? 2 : 3) && ed->right == (dir_v > 0 ? 3 : 2));
        }
    }
    fs_crackgraph_free(&g);
    fs_raster_free(&r);
}

/* A wavy crack all around a map that wraps in u (a cylinder): y = 20 + 6 sin(2 pi x / 64 + 1)
 * pixels. It closes on itself, so it has no node; it crosses the seam, so it comes in pieces that
 * lie in [0, 1]^2, and the piece that stops at u = 1 goes on from u = 0 at the same v; its length
 * is that of the sine; it separates fragment 1 (above, larger v) from 2. */
static void test_seam(void)
{
    const int w = 64, h = 40;
    fs_raster r = {0};
    blank_raster(&r, w, h);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            size_t k = (size_t)j * w + i;
            double yc = 20.0 + 6.0 * sin(2.0 * 3.141592653589793 * (i + 0.5) / w + 1.0);
            r.crack[k] = fabs(j + 0.5 - yc) <= 1.6 ? 1.0f : 0.0f;
            r.cell[k] = r.crack[k] >= 0.5f ? 0 : j + 0.5 < yc ? 1 : 2;
        }
    fs_crackgraph_params p = fs_crackgraph_params_default();
    fs_crackgraph g;
    CHECK(fs_crackgraph_build(&r, true, false, &p, &g) == 0);
    CHECK_MSG(g.n_nodes == 0 && g.n_edges == 1, "%d nodes, %d cracks", (int)g.n_nodes, (int)g.n_edges);
    if (g.n_edges == 1) {
        const fs_crack_edge *e = &g.edge[0];
        CHECK(e->node[0] == -1 && e->node[1] == -1);
        CHECK(e->n_pieces >= 2);
        /* Arc length of the sine, by the trapezoid rule on 6400 steps. */
        double len = 0.0;
        for (int s = 0; s < 6400; s++) {
            double x0 = s * w / 6400.0, x1 = (s + 1) * w / 6400.0;
            double y0 = 6.0 * sin(2.0 * 3.141592653589793 * x0 / w + 1.0);
            double y1 = 6.0 * sin(2.0 * 3.141592653589793 * x1 / w + 1.0);
            len += hypot(x1 - x0, y1 - y0);
        }
        CHECK_NEAR(e->length, len, 0.1 * len);
        CHECK((e->left == 1 && e->right == 2) || (e->left == 2 && e->right == 1));
        int at_seam = 0, matched = 0;
        for (int32_t a = e->first_piece; a < e->first_piece + e->n_pieces; a++) {
            const double *end = g.point + 2 * (g.piece_start[a + 1] - 1);
            if (end[0] != 1.0 && end[0] != 0.0)
                continue;
            at_seam++;
            for (int32_t b = e->first_piece; b < e->first_piece + e->n_pieces; b++) {
                const double *start = g.point + 2 * g.piece_start[b];
                matched += start[0] == 1.0 - end[0] && fabs(start[1] - end[1]) < 1e-12;
            }
        }
        CHECK_MSG(at_seam >= 1 && matched == at_seam, "%d pieces end at the seam, %d continue", at_seam, matched);
    }
    for (int32_t q = 0; q < g.piece_start[g.n_pieces]; q++)
        CHECK(g.point[2 * q] >= 0.0 && g.point[2 * q] <= 1.0 && g.point[2 * q + 1] >= 0.0 && g.point[2 * q + 1] <= 1.0);
    CHECK(g.n_adjacent == 1 && g.adjacent[0].a == 1 && g.adjacent[0].b == 2 && g.adjacent[0].contact >= w);
    fs_raster_free(&r);
    fs_crackgraph_free(&g);
}

/* ---- the graph of rendered voronoi maps ---- */

typedef struct {
    fs_raster r;
    bool wrap_u, wrap_v;
} rendered;

static bool render_preset(const char *preset, int size, int cells, rendered *out)
{
    fs_config cfg = fs_config_default();
    char path[1024];
    snprintf(path, sizeof path, "%s/presets/%s.ini", FS_SRCDIR, preset);
    if (fs_preset_load(path, &cfg) < 0)
        return false;
    cfg.mesh.elements = cells;
    fs_result res;
    if (fs_sim_run(&cfg, &res) < 0)
        return false;
    fs_domain d = cfg.domain;
    fs_domain_normalize(&d);
    out->wrap_u = fs_domain_wraps_u(&d);
    out->wrap_v = fs_domain_wraps_v(&d);
    int rc = fs_render_raster(&res.surface, size, size, 2, out->wrap_u, out->wrap_v, &out->r);
    fs_result_free(&res);
    return rc == 0;
}

/* Smallest distance (pixels) between a pixel of fragment a and one of fragment b, looking no
 * farther than limit; wraps on wrapping axes. */
static double fragment_gap(const fs_raster *r, bool wu, bool wv, int a, int b, int limit)
{
    const int w = r->width, h = r->height;
    double best = INFINITY;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            if (r->cell[(size_t)j * w + i] != a)
                continue;
            for (int dj = -limit; dj <= limit; dj++)
                for (int di = -limit; di <= limit; di++) {
                    int x = i + di, y = j + dj;
                    if (wu)
                        x = (x + w) % w;
                    if (wv)
                        y = (y + h) % h;
                    if (x < 0 || y < 0 || x >= w || y >= h || r->cell[(size_t)y * w + x] != b)
                        continue;
                    best = fmin(best, hypot(di, dj));
                }
        }
    return best;
}

/* Facts every graph of a map must show: pieces in [0, 1]^2, fragments exactly those of the cell-id
 * raster, adjacent pairs facing each other across a crack no wider than the widest crack, sides of
 * cracks among the adjacent pairs, junction degrees >= 3, and on wrapping axes no end at a seam:
 * every piece stopping on the seam is continued by a piece starting on the opposite edge. */
static void check_graph(const rendered *m, const fs_crackgraph *g, const char *what)
{
    const fs_raster *r = &m->r;
    const size_t n = (size_t)r->width * (size_t)r->height;
    int out_of_range = 0;
    for (int32_t q = 0; q < g->piece_start[g->n_pieces]; q++)
        out_of_range += !(g->point[2 * q] >= 0.0 && g->point[2 * q] <= 1.0 && g->point[2 * q + 1] >= 0.0 &&
                          g->point[2 * q + 1] <= 1.0);
    CHECK_MSG(out_of_range == 0, "%s: %d points outside [0, 1]^2", what, out_of_range);

    int64_t *area = fs_calloc(65536, sizeof *area);
    for (size_t k = 0; k < n; k++)
        area[r->cell[k]]++;
    int listed_wrong = 0, missing = 0;
    for (int32_t i = 0; i < g->n_fragments; i++) {
        listed_wrong += area[g->fragment[i].id] != g->fragment[i].area;
        area[g->fragment[i].id] = -1;
    }
    for (int id = 1; id < 65536; id++)
        missing += area[id] > 0;
    CHECK_MSG(listed_wrong == 0 && missing == 0, "%s: %d fragments with a wrong area, %d missing", what,
              listed_wrong, missing);
    free(area);

    /* The widest crack: twice the largest distance from a crack pixel to a fragment pixel. */
    int widest = 0;
    for (int32_t e = 0; e < g->n_edges; e++)
        widest = (int)fmax(widest, ceil(g->edge[e].width));
    int far_apart = 0;
    for (int32_t k = 0; k < g->n_adjacent; k++) {
        double gap = fragment_gap(r, m->wrap_u, m->wrap_v, g->adjacent[k].a, g->adjacent[k].b, 2 * widest + 4);
        far_apart += !(gap <= 2 * widest + 4);
    }
    CHECK_MSG(far_apart == 0, "%s: %d of %d adjacent pairs do not face each other across a crack", what,
              far_apart, (int)g->n_adjacent);
    int sides_unpaired = 0;
    for (int32_t e = 0; e < g->n_edges; e++) {
        const fs_crack_edge *ed = &g->edge[e];
        if (ed->left && ed->right && ed->left != ed->right)
            sides_unpaired += find_pair(g, ed->left, ed->right) == NULL;
    }
    CHECK_MSG(sides_unpaired == 0, "%s: %d cracks separate fragments not listed as adjacent", what, sides_unpaired);

    int low_degree = 0;
    for (int32_t i = 0; i < g->n_nodes; i++)
        low_degree += g->node[i].kind == FS_CRACK_JUNCTION && g->node[i].degree < 3;
    CHECK(low_degree == 0);

    int unmatched = 0, seam_ends = 0;
    for (int32_t a = 0; a < g->n_pieces; a++) {
        for (int s = 0; s < 2; s++) {
            const double *p = g->point + 2 * (s ? g->piece_start[a + 1] - 1 : g->piece_start[a]);
            for (int axis = 0; axis < 2; axis++) {
                if (!(axis ? m->wrap_v : m->wrap_u) || (p[axis] != 0.0 && p[axis] != 1.0))
                    continue;
                bool found = false;
                for (int32_t b = 0; b < g->n_pieces && !found; b++)
                    for (int t = 0; t < 2 && !found; t++) {
                        const double *q = g->point + 2 * (t ? g->piece_start[b + 1] - 1 : g->piece_start[b]);
                        found = q[axis] == 1.0 - p[axis] && fabs(q[1 - axis] - p[1 - axis]) < 1e-9;
                    }
                unmatched += !found;
            }
        }
    }
    for (int32_t i = 0; i < g->n_nodes; i++) {
        const fs_crack_node *nd = &g->node[i];
        if (nd->kind == FS_CRACK_JUNCTION)
            continue;
        double du = fmin(nd->uv[0], 1.0 - nd->uv[0]) * r->width, dv = fmin(nd->uv[1], 1.0 - nd->uv[1]) * r->height;
        seam_ends += (m->wrap_u && du < 3.0) || (m->wrap_v && dv < 3.0);
    }
    CHECK_MSG(unmatched == 0 && seam_ends == 0, "%s: %d pieces stop on a seam unmatched, %d ends at a seam", what,
              unmatched, seam_ends);
}

/* The seamless voronoi tile: a graph on a torus whose faces are the cells, so V - E + F = 0
 * (Euler characteristic of the torus); Voronoi vertices are where three cells meet, so junctions
 * are mostly of degree 3; there are no crack tips, and every fragment has at least three
 * neighbours. */
static void test_voronoi_tile(void)
{
    rendered m = {0};
    CHECK(render_preset("voronoi-tile", 256, 150, &m));
    fs_crackgraph_params p = fs_crackgraph_params_default();
    fs_crackgraph g;
    CHECK(fs_crackgraph_build(&m.r, m.wrap_u, m.wrap_v, &p, &g) == 0);
    check_graph(&m, &g, "voronoi-tile");
    int junctions = 0, degree3 = 0, ends = 0;
    for (int32_t i = 0; i < g.n_nodes; i++) {
        junctions += g.node[i].kind == FS_CRACK_JUNCTION;
        degree3 += g.node[i].kind == FS_CRACK_JUNCTION && g.node[i].degree == 3;
        ends += g.node[i].kind != FS_CRACK_JUNCTION;
    }
    CHECK_MSG(degree3 >= 0.9 * junctions, "%d of %d junctions have degree 3", degree3, junctions);
    CHECK_MSG(ends == 0, "%d crack ends on a voronoi tile", ends);
    int euler = (int)g.n_nodes - (int)g.n_edges + (int)g.n_fragments;
    CHECK_MSG(euler == 0, "V - E + F = %d - %d + %d = %d", (int)g.n_nodes, (int)g.n_edges, (int)g.n_fragments,
              euler);
    int few = 0;
    int32_t *degree = fs_calloc(65536, sizeof *degree);
    for (int32_t k = 0; k < g.n_adjacent; k++) {
        degree[g.adjacent[k].a]++;
        degree[g.adjacent[k].b]++;
    }
    for (int32_t i = 0; i < g.n_fragments; i++)
        few += degree[g.fragment[i].id] < 3;
    free(degree);
    CHECK_MSG(few == 0, "%d fragments with fewer than three neighbours", few);
    fs_crackgraph_free(&g);
    fs_raster_free(&m.r);
}

/* A bounded voronoi plane: cracks run out of the border (border ends on u or v = 0 or 1), none
 * stop inside. Closing the graph with the border (B more edges along it, one outer face) makes a
 * planar graph, V - (E + B) + (F + 1) = 2, so V - E + F - B = 1. */
static void test_voronoi_plane(void)
{
    rendered m = {0};
    CHECK(render_preset("voronoi-plane", 200, 120, &m));
    fs_crackgraph_params p = fs_crackgraph_params_default();
    fs_crackgraph g;
    CHECK(fs_crackgraph_build(&m.r, m.wrap_u, m.wrap_v, &p, &g) == 0);
    check_graph(&m, &g, "voronoi-plane");
    int borders = 0, ends = 0, off_border = 0;
    for (int32_t i = 0; i < g.n_nodes; i++) {
        const fs_crack_node *nd = &g.node[i];
        borders += nd->kind == FS_CRACK_BORDER;
        ends += nd->kind == FS_CRACK_END;
        if (nd->kind == FS_CRACK_BORDER)
            off_border += !(nd->uv[0] == 0.0 || nd->uv[0] == 1.0 || nd->uv[1] == 0.0 || nd->uv[1] == 1.0);
    }
    CHECK_MSG(borders >= 8 && ends == 0 && off_border == 0, "%d border ends (%d off the border), %d ends", borders,
              off_border, ends);
    int euler = (int)g.n_nodes - (int)g.n_edges + (int)g.n_fragments - borders;
    CHECK_MSG(euler == 1, "V - E + F - B = %d - %d + %d - %d = %d", (int)g.n_nodes, (int)g.n_edges,
              (int)g.n_fragments, borders, euler);
    fs_crackgraph_free(&g);
    fs_raster_free(&m.r);
}

/* The sphere wraps in longitude only. */
static void test_voronoi_sphere(void)
{
    rendered m = {0};
    CHECK(render_preset("voronoi-sphere", 256, 200, &m));
    fs_crackgraph_params p = fs_crackgraph_params_default();
    fs_crackgraph g;
    CHECK(fs_crackgraph_build(&m.r, m.wrap_u, m.wrap_v, &p, &g) == 0);
    check_graph(&m, &g, "voronoi-sphere");
    fs_crackgraph_free(&g);
    fs_raster_free(&m.r);
}

int main(void)
{
    RUN(test_t_junction);
    RUN(test_seam);
    RUN(test_voronoi_tile);
    RUN(test_voronoi_plane);
    RUN(test_voronoi_sphere);
    return check_finish();
}
