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

/* The closed 3-D pieces of a model whose fragments are real solids (the tetrahedral model): what
 * --mesh and --asset write for it instead of the lifted texture-space surface (model/model.h,
 * fs_model_solid). World positions in cm (as fs_domain_embed places the domain, the layer outside
 * it); each piece owns its positions (pieces never share one), its triangles counter-clockwise seen
 * from outside, each corner with texture coordinates (v up the maps; near [0, 1], outside it where a
 * piece crosses a seam). */
typedef struct {
    int32_t n_pos;
    double *pos;     /* 3 per position */
    int32_t n_tris;
    int32_t *tri;    /* 3 positions per triangle */
    float *uv;       /* 6 per triangle: (u, v) of each corner */
    uint8_t *wall;   /* per triangle: 0 on the layer's top, 1 elsewhere (crack walls, sides, bottom) */
    int32_t cap_pos;  /* doubles allocated in pos */
    int32_t cap_tris; /* triangles allocated */
} fs_solid;

/* Appends a position (returns its index) or a triangle (uv: its corners' 6 values). */
int32_t fs_solid_add_position(fs_solid *s, const double p[3]);
void fs_solid_add_tri(fs_solid *s, const int32_t v[3], const float uv[6], int wall);
void fs_solid_free(fs_solid *s);

#endif
