/* Ambient occlusion from the height raster: depth below a blurred height (see occlusion.h). */
#include "render/occlusion.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"

fs_occlusion_params fs_occlusion_params_default(void)
{
    return (fs_occlusion_params){.radius = 0.01, .strength = 1.0};
}

static int index_along(int i, int n, bool wrap)
{
    if (wrap) {
        i %= n;
        return i < 0 ? i + n : i;
    }
    return i < 0 ? 0 : i >= n ? n - 1 : i;
}

/* One box filter of radius r along a row of n samples spaced by stride, from src into dst (running sum). */
static void box_line(const double *src, double *dst, int n, size_t stride, int r, bool wrap)
{
    double sum = 0.0;
    for (int k = -r; k <= r; k++)
        sum += src[(size_t)index_along(k, n, wrap) * stride];
    const double inv = 1.0 / (2 * r + 1);
    for (int i = 0; i < n; i++) {
        dst[(size_t)i * stride] = sum * inv;
        sum += src[(size_t)index_along(i + r + 1, n, wrap) * stride] -
               src[(size_t)index_along(i - r, n, wrap) * stride];
    }
}

/* One vertical box filter of radius r over whole rows at once (running sums per column), which
 * reads memory row by row instead of striding down columns. */
static void box_columns(const double *src, double *dst, int w, int h, int r, bool wrap, double *sum)
{
    for (int i = 0; i < w; i++)
        sum[i] = 0.0;
    for (int k = -r; k <= r; k++) {
        const double *row = src + (size_t)index_along(k, h, wrap) * w;
        for (int i = 0; i < w; i++)
            sum[i] += row[i];
    }
    const double inv = 1.0 / (2 * r + 1);
    for (int j = 0; j < h; j++) {
        double *out = dst + (size_t)j * w;
        const double *add = src + (size_t)index_along(j + r + 1, h, wrap) * w;
        const double *sub = src + (size_t)index_along(j - r, h, wrap) * w;
        for (int i = 0; i < w; i++) {
            out[i] = sum[i] * inv;
            sum[i] += add[i] - sub[i];
        }
    }
}

/* Three separable box passes: close to a Gaussian of sigma ~ r (variance r (r + 1)). */
static void blur(double *a, double *tmp, int w, int h, int r, bool wrap_u, bool wrap_v)
{
    double *sum = fs_malloc((size_t)w * sizeof *sum);
    for (int pass = 0; pass < 3; pass++) {
        for (int j = 0; j < h; j++)
            box_line(a + (size_t)j * w, tmp + (size_t)j * w, w, 1, r, wrap_u);
        box_columns(tmp, a, w, h, r, wrap_v, sum);
    }
    free(sum);
}

int fs_occlusion_build(const fs_raster *r, const fs_occlusion_params *p, bool wrap_u, bool wrap_v, fs_image *out)
{
    const int w = r->width, h = r->height;
    const size_t n = (size_t)w * (size_t)h;
    fs_image_alloc(out, w, h, 1, FS_PIX_U8);
    uint8_t *ao = out->data;
    double h_min = r->height_cm[0], h_max = r->height_cm[0];
    for (size_t k = 1; k < n; k++) {
        h_min = fmin(h_min, r->height_cm[k]);
        h_max = fmax(h_max, r->height_cm[k]);
    }
    const double range = h_max - h_min;
    if (!(range > 0.0)) {
        memset(ao, 255, n);
        return 0;
    }
    int radius = (int)lround(p->radius * (w < h ? w : h));
    if (radius < 1)
        radius = 1;
    double *b = fs_malloc(n * sizeof *b), *tmp = fs_malloc(n * sizeof *tmp);
    for (size_t k = 0; k < n; k++)
        b[k] = r->height_cm[k];
    blur(b, tmp, w, h, radius, wrap_u, wrap_v);
    for (size_t k = 0; k < n; k++) {
        double cavity = (b[k] - r->height_cm[k]) / range;
        double v = 1.0 - p->strength * (cavity > 0.0 ? cavity : 0.0);
        v = v < 0.0 ? 0.0 : v;
        ao[k] = (uint8_t)floor(v * 255.0 + 0.5);
    }
    free(b);
    free(tmp);
    return 0;
}
