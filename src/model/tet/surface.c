/* The tetrahedral model's render surface: its top and crack walls in texture space, from the displaced 3-D layer. */
#include "model/tet/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "geom/sphere_surface.h"

/* Where a face goes: top (crack 0, the fragment's cell) or wall (crack 1, cell 0). */
typedef enum { FACE_HIDDEN = 0, FACE_TOP, FACE_WALL } face_kind;

/* A face held by one element: on the substrate (all corners zeta 0: hidden below the layer), on a
 * side of a plane that does not wrap (every corner on a side: the tile's edge, not a crack), on the
 * top (all corners zeta 1, facing up), or a crack wall. */
static face_kind classify(const fs_tet *s, int32_t t, int f)
{
    const fs_tetmesh *m = &s->mesh;
    const int *fc = fs_tet_face[f];
    int bottom = 0, top = 0, side = 0;
    double ex = fs_domain_extent_x(&m->domain), ey = fs_domain_extent_y(&m->domain);
    for (int k = 0; k < 3; k++) {
        int32_t v = m->tet[4 * (size_t)t + fc[k]];
        const double *p = m->pos + 3 * (size_t)v;
        bottom += m->zeta[v] == 0.0;
        top += m->zeta[v] == 1.0;
        if (m->domain.type != FS_DOMAIN_SPHERE)
            side += (m->period[0] == 0.0 && (p[0] == 0.0 || p[0] == ex)) ||
                    (m->period[1] == 0.0 && (p[1] == 0.0 || p[1] == ey));
    }
    if (bottom == 3 || side == 3)
        return FACE_HIDDEN;
    if (top == 3) {
        double x[12], e1[3], e2[3], n[3], up[3], c[3] = {0, 0, 0};
        fs_tetmesh_corners(m, t, x);
        fs_sub3(e1, x + 3 * fc[1], x + 3 * fc[0]);
        fs_sub3(e2, x + 3 * fc[2], x + 3 * fc[0]);
        fs_cross3(n, e1, e2);
        if (m->domain.type == FS_DOMAIN_SPHERE) {
            for (int k = 0; k < 3; k++)
                c[k] = x[3 * fc[0] + k];
            double r = fs_norm3(c);
            for (int k = 0; k < 3; k++)
                up[k] = c[k] / r;
        } else {
            up[0] = up[1] = 0.0;
            up[2] = 1.0;
        }
        return fs_dot3(n, up) > 0.0 ? FACE_TOP : FACE_HIDDEN;
    }
    return FACE_WALL;
}

/* The substrate's radius along direction d (unit) on the growing sphere at time t. */
static double substrate_radius(const fs_tet *s, const double d[3])
{
    double a = fs_growth_radius(&s->growth, s->time), c = fs_growth_radius_z(&s->growth, s->time);
    return 1.0 / sqrt((d[0] * d[0] + d[1] * d[1]) / (a * a) + d[2] * d[2] / (c * c));
}

/* The displacement of node i as the surface and the pieces draw it (3 values): its part across the
 * layer (along the layer's normal at the node) as simulated, its part in the layer's plane times
 * [render] opening_scale, which draws every crack that many times as open as it is (as the wedge
 * and shell models do). */
static void drawn_displacement(const fs_tet *s, int32_t i, const double *c, double u[3])
{
    double n[3];
    fs_tet_displacement(s, i, c, u);
    fs_tet_normal(s, i, n);
    double un = fs_dot3(u, n), scale = s->cfg.opening_scale;
    for (int k = 0; k < 3; k++)
        u[k] = un * n[k] + scale * (u[k] - un * n[k]);
}

typedef struct {
    fs_surface *out;
    double height[3], crack, cell, shade;
} sphere_face;

static int32_t sphere_vertex(void *user, double u, double v, const double w[3])
{
    sphere_face *f = user;
    double h = w[0] * f->height[0] + w[1] * f->height[1] + w[2] * f->height[2];
    return fs_surface_add_vertex(f->out, u, v, h, f->crack, f->cell, f->shade);
}

int fs_tet_surface(const fs_tet *s, fs_surface *out)
{
    const fs_tetmesh *m = &s->mesh;
    double c[FS_TET_LOADS];
    fs_tet_coefficients(s, s->time, c);
    int32_t *adj = fs_malloc((4 * (size_t)m->n_tets + 1) * sizeof *adj);
    int32_t *comp = fs_malloc(((size_t)m->n_tets + 1) * sizeof *comp);
    fs_tetmesh_adjacency(m, adj);
    fs_tetmesh_components(m, adj, comp);
    bool sphere = m->domain.type == FS_DOMAIN_SPHERE;
    double ex = fs_domain_extent_x(&m->domain), ey = fs_domain_extent_y(&m->domain);
    fs_sphere_refiner refiner = {&m->domain, 2e-3, out, sphere_vertex, NULL};
    for (int32_t h = 0; h < 4 * m->n_tets; h++) {
        if (adj[h] >= 0)
            continue;
        int32_t t = h / 4;
        face_kind kind = classify(s, t, h % 4);
        if (kind == FACE_HIDDEN)
            continue;
        double cell = kind == FACE_TOP ? (double)(comp[t] % 65535 + 1) : 0.0;
        double shade = kind == FACE_TOP ? fs_rand_range(s->cfg.seed, FS_RNG_CELL_COLOR, (uint64_t)comp[t], -1.0, 1.0)
                                        : 0.0;
        double crack = kind == FACE_WALL ? 1.0 : 0.0;
        const int *fc = fs_tet_face[h % 4];
        double p[3][3];
        for (int k = 0; k < 3; k++) {
            double u[3];
            fs_tetmesh_corner(m, t, fc[k], p[k]);
            drawn_displacement(s, m->tet[4 * (size_t)t + fc[k]], c, u);
            for (int a = 0; a < 3; a++)
                p[k][a] += u[a];
        }
        if (sphere) {
            sphere_face f = {out, {0, 0, 0}, crack, cell, shade};
            for (int k = 0; k < 3; k++) {
                double r = fs_norm3(p[k]), d[3] = {p[k][0] / r, p[k][1] / r, p[k][2] / r};
                f.height[k] = r - substrate_radius(s, d);
            }
            refiner.user = &f;
            fs_sphere_triangle(&refiner, p[0], p[1], p[2]);
            continue;
        }
        int32_t v[3];
        for (int k = 0; k < 3; k++)
            v[k] = fs_surface_add_vertex(out, p[k][0] / ex, p[k][1] / ey, p[k][2], crack, cell, shade);
        fs_surface_add_tri(out, v[0], v[1], v[2]);
    }
    free(adj);
    free(comp);
    return 0;
}

/* ---- closed pieces ---- */

/* Where a corner of a piece goes: (piece, node, total shift) -> position, in an open-addressing
 * table (the pieces touch nowhere, so a node two pieces share gets a position in each). */
typedef struct {
    int32_t piece, node, sx, sy, pos;
} piece_corner;

typedef struct {
    size_t size;
    piece_corner *slot;
} corner_table;

static uint64_t corner_hash(int32_t piece, int32_t node, int32_t sx, int32_t sy)
{
    uint64_t h = (uint64_t)(uint32_t)node * UINT64_C(0x9e3779b97f4a7c15) ^ (uint64_t)(uint32_t)piece;
    h = (h ^ (h >> 31)) * UINT64_C(0xbf58476d1ce4e5b9) ^ ((uint64_t)(uint8_t)sx << 8 | (uint8_t)sy);
    return (h ^ (h >> 29)) * UINT64_C(0x94d049bb133111eb);
}

static piece_corner *corner_slot(corner_table *tab, int32_t piece, int32_t node, int32_t sx, int32_t sy)
{
    size_t k = (size_t)corner_hash(piece, node, sx, sy) & (tab->size - 1);
    while (tab->slot[k].pos >= 0) {
        piece_corner *c = &tab->slot[k];
        if (c->piece == piece && c->node == node && c->sx == sx && c->sy == sy)
            return c;
        k = (k + 1) & (tab->size - 1);
    }
    return &tab->slot[k];
}

/* The place in space of a displaced material point of the layer. */
static void embed(const fs_tet *s, const double p[3], double out[3])
{
    const fs_domain *d = &s->mesh.domain;
    if (d->type == FS_DOMAIN_CYLINDER) {
        double a = p[0] / d->radius, r = d->radius + p[2];
        out[0] = r * cos(a);
        out[1] = r * sin(a);
        out[2] = p[1];
        return;
    }
    memcpy(out, p, 3 * sizeof *out);
}

/* Texture coordinates of a material point (unwrapped coordinates on the plane and cylinder). */
static void texture_point(const fs_tet *s, const double p[3], float uv[2])
{
    const fs_domain *d = &s->mesh.domain;
    if (d->type == FS_DOMAIN_SPHERE) {
        double q[3], r = fs_norm3(p), t[2];
        for (int k = 0; k < 3; k++)
            q[k] = p[k] / r * d->radius;
        fs_domain_to_uv(d, q, t);
        uv[0] = (float)t[0];
        uv[1] = (float)t[1];
        return;
    }
    uv[0] = (float)(p[0] / fs_domain_extent_x(d));
    uv[1] = (float)(p[1] / fs_domain_extent_y(d));
}

int fs_tet_solid(const fs_tet *s, fs_solid *out)
{
    const fs_tetmesh *m = &s->mesh;
    int32_t nt = m->n_tets;
    double c[FS_TET_LOADS];
    fs_tet_coefficients(s, s->time, c);
    int32_t *adj = fs_malloc((4 * (size_t)nt + 1) * sizeof *adj);
    int32_t *comp = fs_malloc(((size_t)nt + 1) * sizeof *comp);
    fs_tetmesh_adjacency(m, adj);
    fs_tetmesh_components(m, adj, comp);
    /* each tetrahedron's shift within its piece: neighbours agree on the corners they share */
    int32_t *offset = fs_malloc((2 * (size_t)nt + 1) * sizeof *offset);
    uint8_t *done = fs_calloc((size_t)nt + 1, 1);
    int32_t *queue = fs_malloc(((size_t)nt + 1) * sizeof *queue);
    for (int32_t t0 = 0; t0 < nt; t0++) {
        if (done[t0])
            continue;
        int32_t head = 0, tail = 0;
        queue[tail++] = t0;
        done[t0] = 1;
        offset[2 * t0] = offset[2 * t0 + 1] = 0;
        while (head < tail) {
            int32_t t = queue[head++];
            for (int f = 0; f < 4; f++) {
                int32_t o = adj[4 * (size_t)t + f];
                if (o < 0 || done[o])
                    continue;
                int cv = fs_tet_face[f][0];
                int32_t v = m->tet[4 * (size_t)t + cv];
                int co = 0;
                while (m->tet[4 * (size_t)o + co] != v)
                    co++;
                for (int a = 0; a < 2; a++)
                    offset[2 * o + a] = offset[2 * t + a] + m->shift[8 * (size_t)t + 2 * cv + a] -
                                        m->shift[8 * (size_t)o + 2 * co + a];
                done[o] = 1;
                queue[tail++] = o;
            }
        }
    }
    free(queue);
    free(done);
    size_t corners = 0;
    for (int32_t h = 0; h < 4 * nt; h++)
        corners += adj[h] < 0 ? 3 : 0;
    corner_table tab;
    tab.size = 64;
    while (tab.size < 2 * corners)
        tab.size *= 2;
    tab.slot = fs_malloc(tab.size * sizeof *tab.slot);
    for (size_t k = 0; k < tab.size; k++)
        tab.slot[k].pos = -1;
    for (int32_t h = 0; h < 4 * nt; h++) {
        if (adj[h] >= 0)
            continue;
        int32_t t = h / 4;
        const int *fc = fs_tet_face[h % 4];
        int wall = classify(s, t, h % 4) != FACE_TOP;
        int32_t v[3];
        float uv[6];
        for (int k = 0; k < 3; k++) {
            int32_t node = m->tet[4 * (size_t)t + fc[k]];
            int32_t sx = m->shift[8 * (size_t)t + 2 * fc[k]] + offset[2 * t];
            int32_t sy = m->shift[8 * (size_t)t + 2 * fc[k] + 1] + offset[2 * t + 1];
            const double *p0 = m->pos + 3 * (size_t)node;
            double p[3] = {p0[0] + sx * m->period[0], p0[1] + sy * m->period[1], p0[2]};
            texture_point(s, p, uv + 2 * k);
            piece_corner *slot = corner_slot(&tab, comp[t], node, sx, sy);
            if (slot->pos < 0) {
                double u[3], q[3], w[3];
                drawn_displacement(s, node, c, u);
                for (int a = 0; a < 3; a++)
                    q[a] = p[a] + u[a];
                embed(s, q, w);
                *slot = (piece_corner){comp[t], node, sx, sy, fs_solid_add_position(out, w)};
            }
            v[k] = slot->pos;
        }
        if (m->domain.type == FS_DOMAIN_SPHERE)
            for (int k = 1; k < 3; k++) /* one side of the longitude seam */
                uv[2 * k] += uv[2 * k] - uv[0] > 0.5f ? -1.0f : (uv[0] - uv[2 * k] > 0.5f ? 1.0f : 0.0f);
        fs_solid_add_tri(out, v, uv, wall);
    }
    free(tab.slot);
    free(offset);
    free(adj);
    free(comp);
    return 0;
}
