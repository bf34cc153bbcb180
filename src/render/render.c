/* Render meshes: building them, and rasterising them through OSMesa into supersampled, tiled rasters. */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "render/osmesa.h"

fs_render_params fs_render_params_default(void)
{
    /* sRGB (208, 174, 140) clay, (84, 58, 42) crack walls, (40, 28, 22) background, in linear light. */
    fs_render_params p = {
        .width = 1024,
        .height = 1024,
        .supersample = 4,
        .preview_width = 1024,
        .preview_height = 768,
        .height_scale = 1.0,
        .opening_scale = 1.0,
        .wall_slope = 0.0,
        .normal = FS_NORMAL_OPENGL,
        .color_material = {0.630757153f, 0.423267663f, 0.262250662f},    /* sRGB #d0ae8c decoded */
        .color_crack = {0.0886555836f, 0.0423114114f, 0.0231533665f},   /* sRGB #543a2a */
        .color_background = {0.0212190095f, 0.0116122449f, 0.00802319311f}, /* sRGB #281c16 */
        .color_variation = 0.15,
        .roughness = 0.85,
    };
    return p;
}

void fs_raster_free(fs_raster *r)
{
    if (!r)
        return;
    free(r->height_cm);
    free(r->crack);
    free(r->shade);
    free(r->cell);
    memset(r, 0, sizeof *r);
}

/* What an undrawn sample holds: exposed background (height 0, crack 1, cell 0, shade 0). */
static const float clear_attr[4] = {0.0f, 1.0f, 0.0f, 0.0f};

/* One tile of the supersampled target, in global sample coordinates: x from the left, and
 * y_bottom measured from the bottom edge of the whole target (v = 0) up to the tile's lower edge. */
typedef struct {
    int px0, py0;      /* first pixel column, first pixel row from the top */
    int pw, ph;        /* pixels of the tile inside the image */
    double x0, y_bottom;
} tile_window;

/* Everything one render needs besides the mesh. */
typedef struct {
    const fs_surface *m;
    int width, height, ss;
    int tile_w, tile_h;   /* tile size in pixels (the buffer is tile_w*ss x tile_h*ss samples) */
    double su, sv;        /* samples per unit of u and v */
    float *attr;          /* 4 per vertex */
    float *box;           /* 4 per triangle: umin, umax, vmin, vmax */
    float *xyh;           /* 3 per vertex, window coordinates of the current tile and shift */
    uint32_t *list;       /* triangles of the current tile and shift */
    fs_osmesa *gl;
} render_job;

/* Collects the triangles whose shifted bounding box touches the tile (with one sample of slack). */
static int32_t cull_tris(const render_job *j, const tile_window *t, double du, double dv)
{
    const double u_lo = (t->x0 - 1.0) / j->su - du, u_hi = (t->x0 + j->tile_w * j->ss + 1.0) / j->su - du;
    const double v_lo = (t->y_bottom - 1.0) / j->sv - dv, v_hi = (t->y_bottom + j->tile_h * j->ss + 1.0) / j->sv - dv;
    int32_t n = 0;
    for (int32_t k = 0; k < j->m->n_tris; k++) {
        const float *b = j->box + 4 * (size_t)k;
        if (b[1] < u_lo || b[0] > u_hi || b[3] < v_lo || b[2] > v_hi)
            continue;
        j->list[3 * n] = (uint32_t)j->m->tri[3 * k];
        j->list[3 * n + 1] = (uint32_t)j->m->tri[3 * k + 1];
        j->list[3 * n + 2] = (uint32_t)j->m->tri[3 * k + 2];
        n++;
    }
    return n;
}

/* llvmpipe snaps vertices to 1/256 of a sample (8 subpixel bits). */
static const double subpixels = 256.0;

/* Window coordinates of the vertices for one tile and shift. Positions are snapped to the
 * rasteriser's subpixel grid in global sample coordinates before the tile offset is subtracted, so
 * the result is exact in float and the same edge passes through the same samples in every tile. */
static void place_verts(const render_job *j, const tile_window *t, double du, double dv)
{
    const fs_surface *m = j->m;
    for (int32_t i = 0; i < m->n_verts; i++) {
        double x = floor(((double)m->uv[2 * i] + du) * j->su * subpixels + 0.5) / subpixels;
        double y = floor(((double)m->uv[2 * i + 1] + dv) * j->sv * subpixels + 0.5) / subpixels;
        j->xyh[3 * i] = (float)(x - t->x0);
        j->xyh[3 * i + 1] = (float)(y - t->y_bottom);
        j->xyh[3 * i + 2] = m->height[i];
    }
}

/* Box-filters the tile's samples into the raster (sums in double, in index order) and takes the
 * cell id from the centre sample. */
static void resolve_tile(const render_job *j, const tile_window *t, const float *buf, fs_raster *out)
{
    const int ss = j->ss, bw = j->tile_w * ss, bh = j->tile_h * ss;
    const double inv = 1.0 / ((double)ss * ss);
    for (int pj = 0; pj < t->ph; pj++) {
        for (int pi = 0; pi < t->pw; pi++) {
            double h = 0.0, c = 0.0, s = 0.0;
            for (int sj = 0; sj < ss; sj++) {
                /* Buffer rows run bottom to top; image sample rows run top to bottom. */
                const float *row = buf + 4 * ((size_t)(bh - 1 - (pj * ss + sj)) * (size_t)bw + (size_t)(pi * ss));
                for (int si = 0; si < ss; si++) {
                    h += row[4 * si];
                    c += row[4 * si + 1];
                    s += row[4 * si + 3];
                }
            }
            const float *centre = buf + 4 * ((size_t)(bh - 1 - (pj * ss + ss / 2)) * (size_t)bw + (size_t)(pi * ss + ss / 2));
            double cell = floor((double)centre[2] + 0.5);
            if (!(cell >= 0.0))
                cell = 0.0;
            if (cell > 65535.0)
                cell = 65535.0;
            size_t k = (size_t)(t->py0 + pj) * (size_t)j->width + (size_t)(t->px0 + pi);
            out->height_cm[k] = (float)(h * inv);
            out->crack[k] = (float)(c * inv);
            out->shade[k] = (float)(s * inv);
            out->cell[k] = (uint16_t)cell;
        }
    }
}

static int render_tile(render_job *j, const tile_window *t, bool wrap_u, bool wrap_v, double h_lo, double h_hi,
                       fs_raster *out)
{
    if (fs_osmesa_begin(j->gl, clear_attr, h_lo, h_hi) != 0)
        return -1;
    for (int dv = wrap_v ? -1 : 0; dv <= (wrap_v ? 1 : 0); dv++) {
        for (int du = wrap_u ? -1 : 0; du <= (wrap_u ? 1 : 0); du++) {
            int32_t n = cull_tris(j, t, du, dv);
            if (n == 0)
                continue;
            place_verts(j, t, du, dv);
            if (fs_osmesa_draw(j->gl, j->xyh, j->attr, j->list, n) != 0)
                return -1;
        }
    }
    const float *buf = fs_osmesa_finish(j->gl);
    if (!buf)
        return -1;
    resolve_tile(j, t, buf, out);
    return 0;
}

/* design: the supersampled target (width*ss x height*ss samples) is cut into tiles of at most
 * tile_samples^2 samples so memory stays bounded at any map size; each tile gets its own
 * projection by shifting window coordinates (snapped in double, exact in float), and OSMesa never
 * clips a triangle at a tile border (osmesa.c), so every sample sees the same geometry whichever
 * tile holds it. Depth is height (osmesa.h), so the highest surface
 * wins. On wrapping axes each triangle near the tile is also drawn shifted by +-1 period; the
 * culling by bounding box makes that cost nothing for triangles away from the seams. */
int fs_render_raster_tiled(const fs_surface *m, int width, int height, int supersample, bool wrap_u,
                           bool wrap_v, int tile_samples, fs_raster *out)
{
    FS_ASSERT(width > 0 && height > 0 && supersample >= 1 && supersample <= 8 && tile_samples >= 1);
    memset(out, 0, sizeof *out);

    render_job j = {.m = m, .width = width, .height = height, .ss = supersample};
    int tile_px = tile_samples / supersample;
    if (tile_px < 1)
        tile_px = 1;
    j.tile_w = width < tile_px ? width : tile_px;
    j.tile_h = height < tile_px ? height : tile_px;
    j.su = (double)width * supersample;
    j.sv = (double)height * supersample;

    double h_min = 0.0, h_max = 0.0;
    for (int32_t i = 0; i < m->n_verts; i++) {
        double h = m->height[i];
        if (!isfinite(h) || !isfinite(m->uv[2 * i]) || !isfinite(m->uv[2 * i + 1])) {
            fs_error(FS_ERR_INTERNAL, "render: vertex %d has a non-finite position or height", (int)i);
            return -1;
        }
        if (i == 0 || h < h_min)
            h_min = h;
        if (i == 0 || h > h_max)
            h_max = h;
    }
    double pad = 0.01 * (h_max - h_min) + 1e-3 * (1.0 + fabs(h_min) + fabs(h_max));
    double h_lo = h_min - pad, h_hi = h_max + pad;

    j.attr = fs_malloc(4 * ((size_t)m->n_verts + 1) * sizeof *j.attr);
    j.xyh = fs_malloc(3 * ((size_t)m->n_verts + 1) * sizeof *j.xyh);
    j.box = fs_malloc(4 * ((size_t)m->n_tris + 1) * sizeof *j.box);
    j.list = fs_malloc(3 * ((size_t)m->n_tris + 1) * sizeof *j.list);
    for (int32_t i = 0; i < m->n_verts; i++) {
        j.attr[4 * i] = m->height[i];
        j.attr[4 * i + 1] = m->crack[i];
        j.attr[4 * i + 2] = m->cell[i];
        j.attr[4 * i + 3] = m->shade[i];
    }
    for (int32_t k = 0; k < m->n_tris; k++) {
        float *b = j.box + 4 * (size_t)k;
        for (int c = 0; c < 3; c++) {
            int32_t v = m->tri[3 * k + c];
            FS_ASSERT(v >= 0 && v < m->n_verts);
            float u = m->uv[2 * v], w = m->uv[2 * v + 1];
            if (c == 0 || u < b[0])
                b[0] = u;
            if (c == 0 || u > b[1])
                b[1] = u;
            if (c == 0 || w < b[2])
                b[2] = w;
            if (c == 0 || w > b[3])
                b[3] = w;
        }
    }

    size_t n_pix = (size_t)width * (size_t)height;
    out->width = width;
    out->height = height;
    out->height_cm = fs_malloc(n_pix * sizeof *out->height_cm);
    out->crack = fs_malloc(n_pix * sizeof *out->crack);
    out->shade = fs_malloc(n_pix * sizeof *out->shade);
    out->cell = fs_malloc(n_pix * sizeof *out->cell);

    int rc = 0;
    j.gl = fs_osmesa_create(j.tile_w * supersample, j.tile_h * supersample);
    if (!j.gl)
        rc = -1;
    for (int py0 = 0; rc == 0 && py0 < height; py0 += j.tile_h) {
        for (int px0 = 0; rc == 0 && px0 < width; px0 += j.tile_w) {
            tile_window t = {.px0 = px0, .py0 = py0};
            t.pw = width - px0 < j.tile_w ? width - px0 : j.tile_w;
            t.ph = height - py0 < j.tile_h ? height - py0 : j.tile_h;
            t.x0 = (double)px0 * supersample;
            t.y_bottom = (double)(height - py0 - j.tile_h) * supersample;
            rc = render_tile(&j, &t, wrap_u, wrap_v, h_lo, h_hi, out);
        }
    }
    fs_osmesa_destroy(j.gl);
    free(j.attr);
    free(j.xyh);
    free(j.box);
    free(j.list);
    if (rc != 0)
        fs_raster_free(out);
    return rc;
}

int fs_render_raster(const fs_surface *m, int width, int height, int supersample, bool wrap_u, bool wrap_v,
                     fs_raster *out)
{
    return fs_render_raster_tiled(m, width, height, supersample, wrap_u, wrap_v, FS_RENDER_TILE_SAMPLES, out);
}
