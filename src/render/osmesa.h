/* OSMesa context for off-screen rendering (osmesa.c is the only file that includes OSMesa). */
#ifndef FS_RENDER_OSMESA_H
#define FS_RENDER_OSMESA_H

#include <stdbool.h>
#include <stdint.h>

/* An off-screen target: a float RGBA colour buffer and a depth buffer of width x height samples.
 * design: each vertex carries four float attributes drawn as its colour (R = height, G = crack,
 * B = cell, A = shade); colour clamping is switched off, so values outside [0, 1] (cell ids up to
 * 65535, negative shade) arrive in the buffer as the exact floats the rasteriser interpolated.
 * Window coordinates are samples: x right, y up, sample (i, j) centred at (i + 0.5, j + 0.5). */
typedef struct fs_osmesa fs_osmesa;

/* Creates a context and its buffers, current on the calling thread until destroyed. Returns NULL
 * with fs_error(FS_ERR_INTERNAL, "osmesa: ...") when OSMesa cannot provide it, including a size
 * over OSMESA_MAX_WIDTH / OSMESA_MAX_HEIGHT (16384 in Mesa 22.3). */
fs_osmesa *fs_osmesa_create(int width, int height);
void fs_osmesa_destroy(fs_osmesa *g);

/* Clears colour to clear[4] and depth to the far plane, and maps heights in [height_lo, height_hi]
 * onto depth so that the highest surface wins (heights outside the range are clipped away). */
int fs_osmesa_begin(fs_osmesa *g, const float clear[4], double height_lo, double height_hi);

/* Draws n_tris triangles indexing xyh (3 floats per vertex: window x, window y, height) and attr
 * (4 floats per vertex). */
int fs_osmesa_draw(fs_osmesa *g, const float *xyh, const float *attr, const uint32_t *tri, int32_t n_tris);

/* Finishes drawing and returns the colour buffer: width * height RGBA floats, rows from window
 * y = 0 (bottom) up. The pointer stays owned by g and valid until the next begin or destroy. */
const float *fs_osmesa_finish(fs_osmesa *g);

/* ---- The lit pass: a perspective, depth-tested, shadowed, textured view (render/preview.c) ----
 * design: one GLSL program lights each fragment by a directional key light with a shadow map
 * (rendered first from the light, orthographic, filtered 3 x 3 with depth comparison), a
 * hemispherical ambient term and a little Blinn specular; the albedo mixes a per-vertex tint with
 * an sRGB colour texture (decoded to linear by the GL), and the shading normal mixes the vertex
 * normal with a tangent-space normal map, in the same proportion. Drawing goes to a 4x multisampled float
 * target resolved into the context's colour buffer, so edges are anti-aliased; the colour is
 * linear radiance premultiplied by coverage (alpha), on a transparent background. */

/* A mesh of the lit pass, in world coordinates (any unit). */
typedef struct {
    int32_t n_verts;
    const float *pos;    /* 3 per vertex */
    const float *normal; /* 3 per vertex, unit; faces are lit from either side */
    const float *uv;     /* 2 per vertex: coordinates in the colour texture (v up the image) */
    const float *tint;   /* 4 per vertex: linear RGB, and the textures' weight in [0, 1] */
    const float *tangent; /* 6 per vertex: unit directions of increasing texture u and v, the frame
                           * of the normal map (anything where the weight is 0) */
    int32_t n_tris;
    const uint32_t *tri; /* 3 * n_tris vertex indices */
} fs_osmesa_mesh;

/* 8-bit RGB images of the same layout (rows top to bottom, as image/image.h), repeated or clamped per
 * axis: colour in sRGB, and a tangent-space normal map n * 0.5 + 0.5 whose green is
 * normal_green_sign times the v component. */
typedef struct {
    int width, height;
    const uint8_t *rgb;
    int normal_width, normal_height;
    const uint8_t *normal;
    float normal_green_sign;
    bool wrap_u, wrap_v;
} fs_osmesa_texture;

/* Matrices are column-major (OpenGL's order), mapping world coordinates to clip coordinates. */
typedef struct {
    float eye[3];             /* camera position, for the specular term */
    float light_dir[3];       /* unit vector towards the key light */
    float light_rgb[3];       /* key light (linear) */
    float sky_rgb[3];         /* ambient light from `up` */
    float ground_rgb[3];      /* ambient light from below */
    float up[3];              /* unit world up */
    float specular;           /* specular weight, [0, 1] */
    float shininess;          /* Blinn exponent */
    float shadow_from_world[16]; /* the light's orthographic view of the whole scene */
    int shadow_size;          /* shadow map side in texels (0: no shadows) */
    float shadow_offset;      /* world distance along the normal at which shadows are looked up */
} fs_osmesa_scene;

/* Uploads the meshes and the texture (copied: the caller's arrays may be freed afterwards) and
 * renders the shadow map. Returns 0, or -1 with fs_error(FS_ERR_INTERNAL, "osmesa: ...") when a
 * shader does not compile or a target cannot be made. */
int fs_osmesa_lit_load(fs_osmesa *g, const fs_osmesa_scene *s, const fs_osmesa_mesh *meshes, int n_meshes,
                       const fs_osmesa_texture *tex);

/* Draws the loaded scene seen through clip_from_world into the colour buffer (cleared to
 * transparent black); fs_osmesa_finish then returns it. A tiled render passes each tile's
 * sub-frustum. Returns 0 or -1 with fs_error. */
int fs_osmesa_lit_draw(fs_osmesa *g, const float clip_from_world[16]);

/* Releases what fs_osmesa_lit_load made (also done by fs_osmesa_destroy). */
void fs_osmesa_lit_unload(fs_osmesa *g);

#endif
