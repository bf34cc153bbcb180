/* Off-screen rendering of texture-space meshes into float rasters, and rasters into texture maps. */
#ifndef FS_RENDER_RENDER_H
#define FS_RENDER_RENDER_H

#include <stdbool.h>
#include <stdint.h>

#include "io/image.h"

typedef enum { FS_NORMAL_OPENGL = 0, FS_NORMAL_DIRECTX = 1 } fs_normal_convention;

typedef struct {
    int width, height;          /* map size in pixels */
    int supersample;            /* samples per pixel along each axis for anti-aliasing (1..8) */
    double height_scale;        /* exaggeration of height for the normal map */
    fs_normal_convention normal;
    float color_material[3];    /* linear-light RGB of the material top */
    float color_crack[3];       /* crack walls */
    float color_background[3];  /* exposed background at the bottom of cracks */
    double color_variation;     /* per-cell variation of the material colour, [0, 1] */
} fs_render_params;

/* 1024 x 1024, supersample 4, height scale 1, OpenGL normals, a warm clay palette. */
fs_render_params fs_render_params_default(void);

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
    int32_t cap_verts, cap_tris; /* allocated capacities (for fs_render_mesh_add_*) */
} fs_render_mesh;

/* Appends a vertex; returns its index. Grows the arrays as needed. */
int32_t fs_render_mesh_add_vertex(fs_render_mesh *m, double u, double v, double height, double crack,
                                  double cell, double shade);
void fs_render_mesh_add_tri(fs_render_mesh *m, int32_t a, int32_t b, int32_t c);
void fs_render_mesh_free(fs_render_mesh *m);

/* Per-pixel results of a render, area-averaged over the supersamples except cell (centre sample).
 * Pixel convention (all rasters and maps): pixel (i, j) is column i from the left and row j from the
 * top, stored at j * width + i; it covers u in [i/W, (i+1)/W] and v in [1 - (j+1)/H, 1 - j/H], with
 * its centre at u = (i + 0.5)/W, v = 1 - (j + 0.5)/H. So u grows to the right and v grows towards
 * the TOP of the image, which is the +Y (green) direction of an OpenGL normal map.
 * Samples where no triangle was drawn are exposed background: height 0, crack 1, cell 0, shade 0.
 * With an even supersample, "the centre sample" is the one just right of and below the centre. */
typedef struct {
    int width, height;
    float *height_cm; /* cm; background (0) where nothing was drawn */
    float *crack;    /* crack coverage in [0, 1] */
    float *shade;
    uint16_t *cell;  /* fragment id, 0 = crack or nothing */
} fs_raster;

/* Renders m through OSMesa into a width x height raster (tiles internally so that supersampled
 * buffers stay small). wrap_u / wrap_v draw shifted copies so periodic maps have no seam.
 * Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) when OSMesa cannot be set up. */
int fs_render_raster(const fs_render_mesh *m, int width, int height, int supersample, bool wrap_u,
                     bool wrap_v, fs_raster *out);

/* fs_render_raster with an explicit tile limit: tiles hold at most tile_samples x tile_samples
 * supersamples (fs_render_raster uses FS_RENDER_TILE_SAMPLES). The result does not depend on the
 * tiling except for float rounding in interpolated attributes; exposed for tests. */
#define FS_RENDER_TILE_SAMPLES 2048
int fs_render_raster_tiled(const fs_render_mesh *m, int width, int height, int supersample, bool wrap_u,
                           bool wrap_v, int tile_samples, fs_raster *out);
void fs_raster_free(fs_raster *r);

/* The texture maps of SPEC §6 built from a raster. */
typedef struct {
    fs_image height;     /* 1 x u16, linear, 0 = lowest */
    fs_image normal;     /* 3 x u8 RGB tangent-space normal, n * 0.5 + 0.5; green is +v (up the
                          * image) for OpenGL, -v for DirectX */
    fs_image basecolor;  /* 3 x u8 RGB sRGB */
    fs_image crackmask;  /* 1 x u8, 255 = crack */
    fs_image crackdist;  /* 1 x u16, distance to the nearest crack in pixels * crackdist_scale */
    fs_image cellid;     /* 1 x u16 fragment id, 0 = crack */
    double height_min_cm, height_max_cm; /* the range mapped onto 0..65535 */
    double crackdist_scale;              /* map units per pixel of distance */
} fs_maps;

/* Builds all maps; normals and distances wrap across the seam on wrapping axes. cm_per_pixel_u/v
 * give the physical size of a pixel for the normal map. Returns 0 or -1 with fs_error. */
int fs_maps_build(const fs_raster *r, const fs_render_params *p, bool wrap_u, bool wrap_v,
                  double cm_per_pixel_u, double cm_per_pixel_v, fs_maps *out);
void fs_maps_free(fs_maps *m);

#endif
