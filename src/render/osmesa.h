/* OSMesa context for off-screen rendering (osmesa.c is the only file that includes OSMesa). */
#ifndef FS_RENDER_OSMESA_H
#define FS_RENDER_OSMESA_H

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

#endif
