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
