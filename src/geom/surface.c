/* Texture-space surfaces: building them vertex by vertex and triangle by triangle. */
#include "geom/surface.h"

#include <stdlib.h>
#include <string.h>

#include "base/error.h"

static int32_t grow_capacity(int32_t cap, int32_t need)
{
    FS_ASSERT(need > 0 && need < INT32_MAX / 2);
    int32_t c = cap ? cap : 64;
    while (c < need)
        c *= 2;
    return c;
}

int32_t fs_surface_add_vertex(fs_surface *m, double u, double v, double height, double crack, double cell,
                              double shade)
{
    if (m->n_verts == m->cap_verts) {
        int32_t cap = grow_capacity(m->cap_verts, m->n_verts + 1);
        m->uv = fs_realloc(m->uv, 2 * (size_t)cap * sizeof *m->uv);
        m->height = fs_realloc(m->height, (size_t)cap * sizeof *m->height);
        m->crack = fs_realloc(m->crack, (size_t)cap * sizeof *m->crack);
        m->cell = fs_realloc(m->cell, (size_t)cap * sizeof *m->cell);
        m->shade = fs_realloc(m->shade, (size_t)cap * sizeof *m->shade);
        m->cap_verts = cap;
    }
    int32_t i = m->n_verts++;
    m->uv[2 * i] = (float)u;
    m->uv[2 * i + 1] = (float)v;
    m->height[i] = (float)height;
    m->crack[i] = (float)crack;
    m->cell[i] = (float)cell;
    m->shade[i] = (float)shade;
    return i;
}

void fs_surface_add_tri(fs_surface *m, int32_t a, int32_t b, int32_t c)
{
    FS_ASSERT(a >= 0 && a < m->n_verts && b >= 0 && b < m->n_verts && c >= 0 && c < m->n_verts);
    if (m->n_tris == m->cap_tris) {
        int32_t cap = grow_capacity(m->cap_tris, m->n_tris + 1);
        m->tri = fs_realloc(m->tri, 3 * (size_t)cap * sizeof *m->tri);
        m->cap_tris = cap;
    }
    int32_t t = m->n_tris++;
    m->tri[3 * t] = a;
    m->tri[3 * t + 1] = b;
    m->tri[3 * t + 2] = c;
}

void fs_surface_free(fs_surface *m)
{
    if (!m)
        return;
    free(m->uv);
    free(m->height);
    free(m->crack);
    free(m->cell);
    free(m->shade);
    free(m->tri);
    memset(m, 0, sizeof *m);
}

int32_t fs_solid_add_position(fs_solid *s, const double p[3])
{
    if (s->n_pos == s->cap_pos) {
        s->cap_pos = grow_capacity(s->cap_pos, s->n_pos + 1);
        s->pos = fs_realloc(s->pos, 3 * (size_t)s->cap_pos * sizeof *s->pos);
    }
    memcpy(s->pos + 3 * (size_t)s->n_pos, p, 3 * sizeof *p);
    return s->n_pos++;
}

void fs_solid_add_tri(fs_solid *s, const int32_t v[3], const float uv[6], int wall)
{
    if (s->n_tris == s->cap_tris) {
        s->cap_tris = grow_capacity(s->cap_tris, s->n_tris + 1);
        s->tri = fs_realloc(s->tri, 3 * (size_t)s->cap_tris * sizeof *s->tri);
        s->uv = fs_realloc(s->uv, 6 * (size_t)s->cap_tris * sizeof *s->uv);
        s->wall = fs_realloc(s->wall, (size_t)s->cap_tris);
    }
    memcpy(s->tri + 3 * (size_t)s->n_tris, v, 3 * sizeof *v);
    memcpy(s->uv + 6 * (size_t)s->n_tris, uv, 6 * sizeof *uv);
    s->wall[s->n_tris++] = (uint8_t)(wall != 0);
}

void fs_solid_free(fs_solid *s)
{
    if (!s)
        return;
    free(s->pos);
    free(s->tri);
    free(s->uv);
    free(s->wall);
    memset(s, 0, sizeof *s);
}
