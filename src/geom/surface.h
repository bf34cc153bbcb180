/* Texture-space surfaces: the triangle mesh with per-vertex attributes every model hands the renderer. */
#ifndef FS_GEOM_SURFACE_H
#define FS_GEOM_SURFACE_H

#include <stdint.h>

/* A triangle mesh in texture space with per-vertex attributes; what every model hands the renderer.
 * design: the view is orthographic from above and the highest surface wins (depth = height), so
 * crack walls, floors and cell tops can overlap freely. Triangles may extend outside [0,1]^2 by less
 * than one period; on wrapping axes the renderer also draws them shifted by one period. */
typedef struct {
    int32_t n_verts;
    float *uv;       /* 2 * n_verts texture coordinates */
    float *height;   /* n_verts height above the background (cm) */
    float *crack;    /* n_verts: 1 in a crack (gap or wall), 0 on material; drives the crack mask */
    float *cell;     /* n_verts fragment id as an exact small integer (<= 65535), 0 for crack */
    float *shade;    /* n_verts colour variation in [-1, 1] */
    int32_t n_tris;
    int32_t *tri;    /* 3 * n_tris vertex indices */
    int32_t cap_verts, cap_tris; /* allocated capacities (for fs_surface_add_*) */
} fs_surface;

/* Appends a vertex; returns its index. Grows the arrays as needed. */
int32_t fs_surface_add_vertex(fs_surface *m, double u, double v, double height, double crack, double cell,
                              double shade);
void fs_surface_add_tri(fs_surface *m, int32_t a, int32_t b, int32_t c);
void fs_surface_free(fs_surface *m);

#endif
