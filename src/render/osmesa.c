/* Off-screen float rendering through OSMesa (gallium llvmpipe): the only file that includes OSMesa. */
#include "render/osmesa.h"

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <stdbool.h>
#include <stdlib.h>

#include "base/error.h"

/* design: gallium OSMesa (Mesa 22.3) renders into an internal resource of the format chosen by the
 * buffer type (GL_FLOAT gives R32G32B32A32_FLOAT) and copies it to the caller's buffer on glFinish,
 * so attributes keep full float precision without any multi-pass encoding. The fixed-function
 * pipeline clamps vertex colours to [0, 1] unless GL_CLAMP_VERTEX_COLOR is off (glClampColor,
 * GL 3.0 / ARB_color_buffer_float); fragment clamping is switched off too, for good measure. */

/* design: OpenGL clips triangles that leave the viewport, and llvmpipe's clipper makes new vertices
 * whose snapping bends the cut edges by up to half a subpixel, so a sample lying very near an edge
 * could fall on either side depending on where the tile boundary is. The viewport is therefore a
 * power-of-two square much larger than the buffer (the buffer bounds still limit rasterisation
 * exactly), so triangles reaching out of a tile by less than the margin are never clipped, and the
 * window -> clip -> window round trip is exact for coordinates on a 1/256-sample grid. */

struct fs_osmesa {
    OSMesaContext ctx;
    int width, height;
    int viewport;  /* side of the square viewport (a power of two) */
    int margin;    /* viewport extends this many samples beyond the buffer on the left and bottom */
    float *buffer; /* width * height RGBA, rows bottom to top */
};

/* Depth bits asked for; llvmpipe gives 24 (Z24), which resolves height differences of 2^-24 of the
 * drawn height range. */
static const int depth_bits = 32;

static int gl_check(const char *what)
{
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %s failed (GL error 0x%04x)", what, (unsigned)e);
        return -1;
    }
    return 0;
}

fs_osmesa *fs_osmesa_create(int width, int height)
{
    FS_ASSERT(width > 0 && height > 0);
    fs_osmesa *g = fs_calloc(1, sizeof *g);
    g->width = width;
    g->height = height;
    g->buffer = fs_malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    g->ctx = OSMesaCreateContextExt(OSMESA_RGBA, depth_bits, 0, 0, NULL);
    if (!g->ctx) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot create a context");
        goto fail;
    }
    if (!OSMesaMakeCurrent(g->ctx, g->buffer, GL_FLOAT, width, height)) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot bind a %d x %d float colour buffer", width, height);
        goto fail;
    }
    GLint max_w = 0, max_h = 0, y_up = 0, depth = 0;
    OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_w);
    OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_h);
    if (width > max_w || height > max_h) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %d x %d exceeds the largest buffer (%d x %d)", width, height,
                 (int)max_w, (int)max_h);
        goto fail;
    }
    OSMesaGetIntegerv(OSMESA_Y_UP, &y_up);
    glGetIntegerv(GL_DEPTH_BITS, &depth);
    if (!y_up || depth < 16) {
        fs_error(FS_ERR_INTERNAL, "osmesa: unexpected buffer layout (y up %d, %d depth bits)", (int)y_up,
                 (int)depth);
        goto fail;
    }
    PFNGLCLAMPCOLORPROC clamp_color = (PFNGLCLAMPCOLORPROC)OSMesaGetProcAddress("glClampColor");
    if (!clamp_color) {
        fs_error(FS_ERR_INTERNAL, "osmesa: glClampColor is missing (OpenGL 3.0 needed)");
        goto fail;
    }
    clamp_color(GL_CLAMP_VERTEX_COLOR, GL_FALSE);
    clamp_color(GL_CLAMP_FRAGMENT_COLOR, GL_FALSE);
    if (gl_check("disabling colour clamping") != 0)
        goto fail;

    GLint dims[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
    g->viewport = 1;
    while (2 * g->viewport <= dims[0] && 2 * g->viewport <= dims[1])
        g->viewport *= 2;
    int side = width > height ? width : height;
    if (g->viewport < side) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %d x %d exceeds the largest viewport (%d)", width, height,
                 g->viewport);
        goto fail;
    }
    g->margin = (g->viewport - side) / 2;
    glViewport(-g->margin, -g->margin, g->viewport, g->viewport);
    glDisable(GL_DITHER);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_LIGHTING);
    glShadeModel(GL_SMOOTH);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    if (gl_check("setting up the pipeline") != 0)
        goto fail;
    return g;

fail:
    fs_osmesa_destroy(g);
    return NULL;
}

void fs_osmesa_destroy(fs_osmesa *g)
{
    if (!g)
        return;
    if (g->ctx) {
        if (OSMesaGetCurrentContext() == g->ctx)
            OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        OSMesaDestroyContext(g->ctx);
    }
    free(g->buffer);
    free(g);
}

int fs_osmesa_begin(fs_osmesa *g, const float clear[4], double height_lo, double height_hi)
{
    FS_ASSERT(height_hi > height_lo);
    /* Window x, y are buffer samples (the viewport's margin shifts them back); eye z is the height,
     * so near = -height_hi maps to depth 0 and the highest surface passes GL_LESS against everything
     * below it. */
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    double lo = -(double)g->margin, hi = (double)(g->viewport - g->margin);
    glOrtho(lo, hi, lo, hi, -height_hi, -height_lo);
    glMatrixMode(GL_MODELVIEW);
    glClearColor(clear[0], clear[1], clear[2], clear[3]);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    return gl_check("clearing");
}

int fs_osmesa_draw(fs_osmesa *g, const float *xyh, const float *attr, const uint32_t *tri, int32_t n_tris)
{
    (void)g;
    if (n_tris <= 0)
        return 0;
    glVertexPointer(3, GL_FLOAT, 0, xyh);
    glColorPointer(4, GL_FLOAT, 0, attr);
    glDrawElements(GL_TRIANGLES, 3 * n_tris, GL_UNSIGNED_INT, tri);
    return gl_check("drawing");
}

const float *fs_osmesa_finish(fs_osmesa *g)
{
    glFinish();
    if (gl_check("finishing") != 0)
        return NULL;
    return g->buffer;
}
