/* Off-screen rendering of texture-space meshes into float rasters, and rasters into texture maps. */
#ifndef FS_RENDER_RENDER_H
#define FS_RENDER_RENDER_H

#include <stdbool.h>
#include <stdint.h>

#include "geom/domain.h"
#include "geom/surface.h"
#include "image/image.h"

typedef enum { FS_NORMAL_OPENGL = 0, FS_NORMAL_DIRECTX = 1 } fs_normal_convention;

typedef struct {
    int width, height;          /* map size in pixels */
    int supersample;            /* samples per pixel along each axis for anti-aliasing (1..8) */
    int preview_width, preview_height; /* size of the lit 3-D preview image in pixels */
    double height_scale;        /* exaggeration of height for the normal map */
    fs_normal_convention normal;
    float color_material[3];    /* linear-light RGB of the material top */
    float color_crack[3];       /* crack walls */
    float color_background[3];  /* exposed background at the bottom of cracks */
    double color_variation;     /* per-cell variation of the material colour, [0, 1] */
    double roughness;           /* PBR roughness of the surface, [0, 1], for the packed engine maps */
    double opening_scale;       /* the cracks are drawn this many times as open as simulated (the
                                   models' in-plane displacement scaled); read by the model through
                                   fs_model_setup.opening_scale */
    double wall_slope;          /* [0, 1]: the share of each crack's width over which its walls slope
                                   down to its floor (0: upright walls); read by the model through
                                   fs_model_setup.wall_slope */
} fs_render_params;

/* 1024 x 1024, supersample 4, 1024 x 768 preview, height scale 1, OpenGL normals, a warm clay palette. */
fs_render_params fs_render_params_default(void);

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
int fs_render_raster(const fs_surface *m, int width, int height, int supersample, bool wrap_u,
                     bool wrap_v, fs_raster *out);

/* fs_render_raster with an explicit tile limit: tiles hold at most tile_samples x tile_samples
 * supersamples (fs_render_raster uses FS_RENDER_TILE_SAMPLES). The result does not depend on the
 * tiling except for float rounding in interpolated attributes; exposed for tests. */
#define FS_RENDER_TILE_SAMPLES 2048
int fs_render_raster_tiled(const fs_surface *m, int width, int height, int supersample, bool wrap_u,
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

/* A render mesh lifted into 3-D (render/lift.c): what NAME.obj holds and the preview draws.
 * Indices follow Wavefront OBJ: each triangle corner names a position, a texture vertex and a
 * normal separately, so a position on a seam (u = 0 and u = 1 on the cylinder and sphere, the
 * poles) is one vertex with several texture coordinates. */
typedef struct {
    int32_t n_pos;
    double *pos;         /* 3 per position, world cm; no two closer than weld_tolerance unless equal:
                          * equal ones are copies where fragments touch (see fs_render_lift) */
    int32_t n_uv;
    float *uv;           /* 2 per texture vertex, in [0, 1]; v is the maps' v (up the image) */
    int32_t n_normal;
    float *normal;       /* 3 per unit normal */
    int32_t n_tris;
    int32_t *corner;     /* 9 per triangle: (position, uv, normal) of each corner, counter-clockwise
                          * seen from outside (above the layer) */
    uint8_t *wall;       /* per triangle: 1 for a wall the lift added to close a step, else 0 */
    double weld_tolerance; /* cm */
} fs_lifted_mesh;

/* design: each triangle of m is clipped to the texture square (on wrapping axes the pieces outside
 * are shifted back by a period, so every point of the layer appears once with uv in [0, 1]) and
 * each vertex is placed at the domain point of its uv (fs_domain_from_uv, fs_domain_embed), moved
 * by height * height_scale along the outward normal: plane (u W, v H, h), cylinder and sphere at
 * radius R + h. Positions closer than 2.5e-7 of the domain's size are welded (so the cylinder and
 * sphere close across their seam and at the poles); triangles that collapse are dropped, and
 * coincident ones cancel in pairs. Orientation is made consistent across shared edges, each
 * connected piece facing the way most of its texture-space area says. The render mesh draws a step
 * between two surfaces (a crack floor beside a cell top) as two boundaries over the same line in
 * texture space; the lift closes every such step by a vertical wall of two triangles (and cuts the
 * walls' upright edges where walls of different heights meet), so the result is bounded only along
 * the domain's borders: the four sides of a plane (periodic or not: a tile is a flat slab in 3-D),
 * the two ends of a cylinder, nowhere on a sphere. Where fragments touch only at a corner or along a
 * line (edges of four triangles), positions are copied so that each fragment's surface is a manifold
 * of its own (see split_nonmanifold in lift.c). Corner normals average, weighted by angle, the
 * normals of the triangles around the position within 50 degrees of the corner's own triangle, so
 * walls and tops keep a crisp edge. Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) for a
 * non-finite vertex. */
int fs_render_lift(const fs_surface *m, const fs_domain *d, double height_scale, fs_lifted_mesh *out);
void fs_lifted_mesh_free(fs_lifted_mesh *l);

/* The lifted mesh of a model's closed 3-D pieces (geom/surface.h: fs_solid) in place of
 * fs_render_lift's: the positions as they are (weld_tolerance 0: pieces keep their own), the texture
 * coordinates de-duplicated, corner normals as fs_render_lift makes them, the solid's wall flags.
 * Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) for a non-finite position. */
int fs_render_solid(const fs_solid *s, fs_lifted_mesh *out);

/* Edges (pairs of position indices) used by exactly one triangle, in the direction their triangle
 * runs along them: 2 * count entries in *edges (caller frees); returns the count. *n_bad (if not
 * NULL) gets the number of edges with more than two triangles or two running the same way: none in
 * a manifold, consistently oriented mesh. (The lift leaves such edges where a model's surfaces
 * meet four around one point at alternating heights, or overlap.) */
int32_t fs_lifted_mesh_boundary(const fs_lifted_mesh *l, int32_t **edges, int32_t *n_bad);

/* The corners of l as vertices for drawing: one per distinct (position, texture vertex, normal),
 * *vert holding those three indices per vertex, and 3 vertex indices per triangle in *tri (caller
 * frees both). Returns the number of vertices. */
int32_t fs_lifted_mesh_vertices(const fs_lifted_mesh *l, int32_t **vert, uint32_t **tri);

/* The lit perspective 3-D view of SPEC §6 (render/preview.c): the lifted render mesh (heights times
 * p->height_scale) textured with maps->basecolor and lit through maps->normal (whose convention is
 * p->normal), shown as a slab for a plane, a trunk segment for a cylinder and a globe for a
 * sphere, into a p->preview_width x p->preview_height RGB 8-bit sRGB image (allocated into *out).
 * Deterministic for a given mesh on a given machine. Returns 0, or -1 with fs_error
 * (FS_ERR_DATA for a size outside 16..16384, FS_ERR_INTERNAL when OSMesa fails). */
int fs_render_preview(const fs_surface *m, const fs_domain *d, const fs_render_params *p, const fs_maps *maps,
                      fs_image *out);

#endif
