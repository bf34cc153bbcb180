/* Texture maps (SPEC §6) from a rendered raster: height, normal, basecolor, crack mask, distance, cell id. */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"

/* Crack distance map units per pixel: 1/256 pixel resolution, saturating at 255.996 pixels. */
static const double crackdist_units_per_pixel = 256.0;

/* How much darker the lowest part of a bevel is than the top of its cell. */
static const double bevel_darkening = 0.2;

/* Heights within this fraction of the range above the lowest point show the background colour
 * (fading out linearly up to it). */
static const double background_band = 0.05;

static uint8_t unit_to_u8(double x)
{
    if (!(x > 0.0))
        return 0;
    if (x >= 1.0)
        return 255;
    return (uint8_t)floor(x * 255.0 + 0.5);
}

static uint16_t to_u16(double x)
{
    if (!(x > 0.0))
        return 0;
    if (x >= 65535.0)
        return 65535;
    return (uint16_t)floor(x + 0.5);
}

static double clamp01(double x)
{
    return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
}

static double linear_to_srgb(double c)
{
    c = clamp01(c);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

/* design: encoding every channel of a 4096^2 map with pow() costs about a second, so the encoder
 * keeps, for each 8-bit code k >= 1, the smallest linear value that encodes to k (found by
 * bisection on the exact formula) and looks codes up by binary search: the same bytes as
 * unit_to_u8(linear_to_srgb(c)), in 8 comparisons. */
typedef struct {
    double lowest[256]; /* lowest[k]: smallest linear value encoding to code k (k >= 1) */
} srgb_encoder;

static void srgb_encoder_init(srgb_encoder *e)
{
    e->lowest[0] = -INFINITY;
    for (int k = 1; k < 256; k++) {
        double lo = 0.0, hi = 1.0; /* code(lo) < k <= code(hi) */
        while (nextafter(lo, 2.0) < hi) {
            double mid = 0.5 * (lo + hi);
            if (unit_to_u8(linear_to_srgb(mid)) >= k)
                hi = mid;
            else
                lo = mid;
        }
        e->lowest[k] = hi;
    }
}

static uint8_t srgb_encode(const srgb_encoder *e, double c)
{
    int k = 0;
    for (int step = 128; step > 0; step >>= 1)
        if (c >= e->lowest[k + step])
            k += step;
    return (uint8_t)k;
}

/* Neighbours of index i along an axis of n pixels: wrapped, or clamped at the border. Returns the
 * number of pixel steps between them (0 when the axis has a single pixel). */
static int neighbours(int i, int n, bool wrap, int *lo, int *hi)
{
    if (n == 1) {
        *lo = *hi = 0;
        return 0;
    }
    if (wrap) {
        *lo = i > 0 ? i - 1 : n - 1;
        *hi = i < n - 1 ? i + 1 : 0;
        return 2;
    }
    *lo = i > 0 ? i - 1 : 0;
    *hi = i < n - 1 ? i + 1 : n - 1;
    return *hi - *lo;
}

/* design: tangent-space normal of the height field z = s * h(u, v) (s = height_scale), with the
 * gradient from central differences in cm per cm: n = normalize(-s dh/du, -s dh/dv, 1), where
 * +v points to the top of the image (render.h). OpenGL maps store n.y in green; DirectX stores -n.y
 * as the bitwise inverse 255 - g of the OpenGL byte, so the two maps differ exactly by a green flip.
 * A surface rising towards the top of the image faces down (-v), so its OpenGL green is below 128. */
static void build_normal(const fs_raster *r, const fs_render_params *p, bool wrap_u, bool wrap_v, double cm_u,
                         double cm_v, fs_image *img)
{
    const int w = r->width, h = r->height;
    const double s = p->height_scale;
    const bool directx = p->normal == FS_NORMAL_DIRECTX;
    uint8_t *px = img->data;
    for (int j = 0; j < h; j++) {
        int up, down;
        /* Row j - 1 is towards the top (+v), row j + 1 towards the bottom. */
        int steps_v = neighbours(j, h, wrap_v, &up, &down);
        for (int i = 0; i < w; i++) {
            int left, right;
            int steps_u = neighbours(i, w, wrap_u, &left, &right);
            double dhdu = 0.0, dhdv = 0.0;
            if (steps_u > 0)
                dhdu = ((double)r->height_cm[(size_t)j * w + right] - r->height_cm[(size_t)j * w + left]) /
                       (steps_u * cm_u);
            if (steps_v > 0)
                dhdv = ((double)r->height_cm[(size_t)up * w + i] - r->height_cm[(size_t)down * w + i]) /
                       (steps_v * cm_v);
            double nx = -s * dhdu, ny = -s * dhdv, nz = 1.0;
            double len = sqrt(nx * nx + ny * ny + nz * nz);
            nx /= len;
            ny /= len;
            nz /= len;
            uint8_t *o = px + 3 * ((size_t)j * w + i);
            o[0] = unit_to_u8(nx * 0.5 + 0.5);
            o[1] = unit_to_u8(ny * 0.5 + 0.5);
            if (directx)
                o[1] = (uint8_t)(255 - o[1]);
            o[2] = unit_to_u8(nz * 0.5 + 0.5);
        }
    }
}

/* Material colour varied per cell by shade, darkened down the bevel, covered by the crack colour by
 * crack coverage and by the background colour at the very bottom; linear light until the final
 * sRGB encoding. */
static void build_basecolor(const fs_raster *r, const fs_render_params *p, double h_min, double h_max,
                            fs_image *img)
{
    const double range = h_max - h_min;
    srgb_encoder enc;
    srgb_encoder_init(&enc);
    uint8_t *px = img->data;
    size_t n = (size_t)r->width * (size_t)r->height;
    for (size_t k = 0; k < n; k++) {
        double t = range > 0.0 ? ((double)r->height_cm[k] - h_min) / range : 1.0;
        double vary = 1.0 + p->color_variation * r->shade[k];
        if (vary < 0.0)
            vary = 0.0;
        double bevel = 1.0 - bevel_darkening * (1.0 - clamp01(t));
        double cover = clamp01(r->crack[k]);
        double bottom = range > 0.0 ? clamp01(1.0 - t / background_band) : 0.0;
        for (int c = 0; c < 3; c++) {
            double col = p->color_material[c] * vary * bevel;
            col = col * (1.0 - cover) + p->color_crack[c] * cover;
            col = col * (1.0 - bottom) + p->color_background[c] * bottom;
            px[3 * k + (size_t)c] = srgb_encode(&enc, col);
        }
    }
}

int fs_maps_build(const fs_raster *r, const fs_render_params *p, bool wrap_u, bool wrap_v,
                  double cm_per_pixel_u, double cm_per_pixel_v, fs_maps *out)
{
    FS_ASSERT(r->width > 0 && r->height > 0 && cm_per_pixel_u > 0.0 && cm_per_pixel_v > 0.0);
    memset(out, 0, sizeof *out);
    const int w = r->width, h = r->height;
    const size_t n = (size_t)w * (size_t)h;

    uint8_t *mask = fs_malloc(n);
    float *dist = fs_malloc(n * sizeof *dist);
    for (size_t k = 0; k < n; k++)
        mask[k] = r->crack[k] >= 0.5f;
    int rc = fs_image_distance(mask, w, h, wrap_u, wrap_v, dist);
    free(mask);
    if (rc != 0) {
        free(dist);
        return -1;
    }

    double h_min = r->height_cm[0], h_max = r->height_cm[0];
    for (size_t k = 1; k < n; k++) {
        if (r->height_cm[k] < h_min)
            h_min = r->height_cm[k];
        if (r->height_cm[k] > h_max)
            h_max = r->height_cm[k];
    }
    out->height_min_cm = h_min;
    out->height_max_cm = h_max;
    out->crackdist_scale = crackdist_units_per_pixel;

    fs_image_alloc(&out->height, w, h, 1, FS_PIX_U16);
    fs_image_alloc(&out->normal, w, h, 3, FS_PIX_U8);
    fs_image_alloc(&out->basecolor, w, h, 3, FS_PIX_U8);
    fs_image_alloc(&out->crackmask, w, h, 1, FS_PIX_U8);
    fs_image_alloc(&out->crackdist, w, h, 1, FS_PIX_U16);
    fs_image_alloc(&out->cellid, w, h, 1, FS_PIX_U16);

    uint16_t *height = out->height.data, *crackdist = out->crackdist.data, *cellid = out->cellid.data;
    uint8_t *crackmask = out->crackmask.data;
    const double range = h_max - h_min;
    for (size_t k = 0; k < n; k++) {
        height[k] = range > 0.0 ? to_u16(((double)r->height_cm[k] - h_min) / range * 65535.0) : 0;
        crackmask[k] = unit_to_u8(r->crack[k]);
        crackdist[k] = to_u16((double)dist[k] * crackdist_units_per_pixel);
        cellid[k] = r->cell[k];
    }
    free(dist);

    build_normal(r, p, wrap_u, wrap_v, cm_per_pixel_u, cm_per_pixel_v, &out->normal);
    build_basecolor(r, p, h_min, h_max, &out->basecolor);
    return 0;
}

void fs_maps_free(fs_maps *m)
{
    if (!m)
        return;
    fs_image_free(&m->height);
    fs_image_free(&m->normal);
    fs_image_free(&m->basecolor);
    fs_image_free(&m->crackmask);
    fs_image_free(&m->crackdist);
    fs_image_free(&m->cellid);
    memset(m, 0, sizeof *m);
}
