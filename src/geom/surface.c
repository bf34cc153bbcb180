/* Texture-space surfaces: building them vertex by vertex and triangle by triangle. */
#include "geom/surface.h"

#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"

int32_t fs_surface_add_vertex(fs_surface *m, double u, double v, double height, double crack, double cell,
                              double shade)
{
    if (FS_ARRAY_GROW(m->cap_verts, m->n_verts + 1, 64)) {
        FS_ARRAY_RESIZE(m->uv, 2 * (size_t)m->cap_verts);
        FS_ARRAY_RESIZE(m->height, m->cap_verts);
        FS_ARRAY_RESIZE(m->crack, m->cap_verts);
        FS_ARRAY_RESIZE(m->cell, m->cap_verts);
        FS_ARRAY_RESIZE(m->shade, m->cap_verts);
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
    if (FS_ARRAY_GROW(m->cap_tris, m->n_tris + 1, 64))
        FS_ARRAY_RESIZE(m->tri, 3 * (size_t)m->cap_tris);
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
