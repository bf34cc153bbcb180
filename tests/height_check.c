/* Test helper: the written height maps agree with each other (float EXR, 16-bit PNG) and with the normal map. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "image/image.h"

#define PI 3.14159265358979323846

static int load(const char *path, fs_pixel_type type, int channels, fs_image *img)
{
    if (fs_image_read(path, img) < 0) {
        fprintf(stderr, "height_check: %s\n", fs_error_message());
        return -1;
    }
    if (img->type != type || img->channels != channels) {
        fprintf(stderr, "height_check: %s: expected %d channel(s) of type %d, got %d of type %d\n", path, channels,
                (int)type, img->channels, (int)img->type);
        fs_image_free(img);
        return -1;
    }
    return 0;
}

static int parse_number(const char *s, double *x)
{
    char *end;
    *x = strtod(s, &end);
    if (end == s || *end || !isfinite(*x)) {
        fprintf(stderr, "height_check: '%s' is not a number\n", s);
        return -1;
    }
    return 0;
}

/* The PNG's heights in cm: 0 is min_cm, 65535 is max_cm, linear (the sidecar's encoding). */
static double *png_heights_cm(const fs_image *png, double min_cm, double max_cm)
{
    size_t n = (size_t)png->width * (size_t)png->height;
    double *h = malloc(n * sizeof *h);
    const uint16_t *q = png->data;
    for (size_t k = 0; k < n; k++)
        h[k] = min_cm + (double)q[k] / 65535.0 * (max_cm - min_cm);
    return h;
}

/* exr EXR PNG MIN_CM MAX_CM: exit 0 when every pixel of the float EXR (cm) is within half a 16-bit
 * step of the PNG mapped back to cm (the encoder rounds to the nearest step), plus float rounding
 * of the EXR's values and of the range as the sidecar prints it (10 significant digits). Prints the
 * largest difference in cm and in steps, and where it is. */
static int exr(char **argv)
{
    double lo, hi;
    if (parse_number(argv[2], &lo) < 0 || parse_number(argv[3], &hi) < 0)
        return 2;
    fs_image e = {0}, p = {0};
    if (load(argv[0], FS_PIX_F32, 1, &e) < 0 || load(argv[1], FS_PIX_U16, 1, &p) < 0)
        return 2;
    if (e.width != p.width || e.height != p.height || !(hi > lo)) {
        fprintf(stderr, "height_check: sizes %dx%d and %dx%d, range [%g, %g]\n", e.width, e.height, p.width,
                p.height, lo, hi);
        return 1;
    }
    const double step = (hi - lo) / 65535.0;
    const double magnitude = fmax(fabs(lo), fabs(hi));
    const double allowed = 0.5 * step + 4.0 * FLT_EPSILON * magnitude + 1e-9 * magnitude;
    double *h = png_heights_cm(&p, lo, hi);
    const float *f = e.data;
    double worst = 0.0, e_lo = INFINITY, e_hi = -INFINITY;
    size_t n = (size_t)e.width * (size_t)e.height, at = 0, over = 0;
    for (size_t k = 0; k < n; k++) {
        double d = fabs((double)f[k] - h[k]);
        if (k == 0 || d > worst) {
            worst = d;
            at = k;
        }
        over += !(d <= allowed);
        e_lo = fmin(e_lo, f[k]);
        e_hi = fmax(e_hi, f[k]);
    }
    printf("max |exr - png| = %.3g cm = %.3f steps of %.3g cm at pixel (%zu, %zu); %zu of %zu pixels over %.3g cm; "
           "exr range [%.9g, %.9g]\n",
           worst, worst / step, step, at % (size_t)e.width, at / (size_t)e.width, over, n, allowed, e_lo, e_hi);
    free(h);
    fs_image_free(&e);
    fs_image_free(&p);
    return over ? 1 : 0;
}

/* Neighbours of index i along an axis of n pixels, wrapped or clamped at the border; returns the
 * number of pixel steps between them (the renderer's central differences, render/maps.c). */
static int neighbours(int i, int n, int wrap, int *lo, int *hi)
{
    if (n == 1) {
        *lo = *hi = i;
        return 0;
    }
    *lo = i > 0 ? i - 1 : wrap ? n - 1 : 0;
    *hi = i < n - 1 ? i + 1 : wrap ? 0 : n - 1;
    return wrap ? 2 : *hi - *lo;
}

/* normal NORMAL HEIGHT MIN_CM MAX_CM SCALE EXTENT_X EXTENT_Y WRAP_U WRAP_V opengl|directx MAX_DEG MEAN_DEG:
 * decodes the 8-bit normal map (n = 2 c / 255 - 1; DirectX green points down the image) and
 * compares it, pixel by pixel, with the normal of the height field SCALE * h, h being the 16-bit
 * height map in cm, its gradient taken by central differences over pixels of EXTENT_X / width by
 * EXTENT_Y / height cm, wrapped across the seam on wrapping axes (WRAP_* 1) and one-sided at other
 * borders; +v is up the image. Prints the mean, 99th percentile and largest angle between the two;
 * exit 0 when the largest is at most MAX_DEG and the mean at most MEAN_DEG. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int normal(char **argv)
{
    double lo, hi, scale, ext_x, ext_y, max_deg, mean_deg;
    if (parse_number(argv[2], &lo) < 0 || parse_number(argv[3], &hi) < 0 || parse_number(argv[4], &scale) < 0 ||
        parse_number(argv[5], &ext_x) < 0 || parse_number(argv[6], &ext_y) < 0 ||
        parse_number(argv[10], &max_deg) < 0 || parse_number(argv[11], &mean_deg) < 0)
        return 2;
    int wrap_u = atoi(argv[7]), wrap_v = atoi(argv[8]);
    int directx = !strcmp(argv[9], "directx");
    if (!directx && strcmp(argv[9], "opengl")) {
        fprintf(stderr, "height_check: convention '%s': expected opengl or directx\n", argv[9]);
        return 2;
    }
    fs_image nm = {0}, hm = {0};
    if (load(argv[0], FS_PIX_U8, 3, &nm) < 0 || load(argv[1], FS_PIX_U16, 1, &hm) < 0)
        return 2;
    if (nm.width != hm.width || nm.height != hm.height) {
        fprintf(stderr, "height_check: the normal map is %dx%d, the height map %dx%d\n", nm.width, nm.height,
                hm.width, hm.height);
        return 1;
    }
    const int w = hm.width, ht = hm.height;
    const double cm_u = ext_x / w, cm_v = ext_y / ht;
    double *h = png_heights_cm(&hm, lo, hi);
    double *angle = malloc((size_t)w * (size_t)ht * sizeof *angle);
    const uint8_t *px = nm.data;
    double sum = 0.0;
    size_t worst_at = 0;
    for (int j = 0; j < ht; j++) {
        int up, down;
        int sv = neighbours(j, ht, wrap_v, &up, &down);
        for (int i = 0; i < w; i++) {
            int left, right;
            int su = neighbours(i, w, wrap_u, &left, &right);
            double dhdu = su ? (h[(size_t)j * w + right] - h[(size_t)j * w + left]) / (su * cm_u) : 0.0;
            /* row j - 1 is up the image, towards +v */
            double dhdv = sv ? (h[(size_t)up * w + i] - h[(size_t)down * w + i]) / (sv * cm_v) : 0.0;
            double want[3] = {-scale * dhdu, -scale * dhdv, 1.0};
            const uint8_t *c = px + 3 * ((size_t)j * w + i);
            double got[3] = {2.0 * c[0] / 255.0 - 1.0, 2.0 * c[1] / 255.0 - 1.0, 2.0 * c[2] / 255.0 - 1.0};
            if (directx)
                got[1] = -got[1];
            double dot = 0.0, lw = 0.0, lg = 0.0;
            for (int q = 0; q < 3; q++) {
                dot += want[q] * got[q];
                lw += want[q] * want[q];
                lg += got[q] * got[q];
            }
            double cosine = lg > 0.0 ? dot / sqrt(lw * lg) : -1.0;
            double a = acos(fmax(-1.0, fmin(1.0, cosine))) * 180.0 / PI;
            size_t k = (size_t)j * w + i;
            angle[k] = a;
            sum += a;
            if (a > angle[worst_at])
                worst_at = k;
        }
    }
    size_t n = (size_t)w * (size_t)ht;
    double worst = angle[worst_at], mean = sum / (double)n;
    qsort(angle, n, sizeof *angle, cmp_double);
    printf("angle between the normal map and the height gradient: mean %.3f, 99%% %.3f, max %.3f degrees "
           "(at pixel (%zu, %zu))\n",
           mean, angle[(size_t)(0.99 * (double)(n - 1))], worst, worst_at % (size_t)w, worst_at / (size_t)w);
    free(angle);
    free(h);
    fs_image_free(&nm);
    fs_image_free(&hm);
    return worst <= max_deg && mean <= mean_deg ? 0 : 1;
}

/* extent plane W H | cylinder R H | sphere R: prints the texture's extent in cm along u and v. */
static int extent(int argc, char **argv)
{
    double a, b = 0.0;
    if (argc < 2 || parse_number(argv[1], &a) < 0 || (argc > 2 && parse_number(argv[2], &b) < 0))
        return 2;
    if (!strcmp(argv[0], "plane") && argc == 3)
        printf("%.17g %.17g\n", a, b);
    else if (!strcmp(argv[0], "cylinder") && argc == 3)
        printf("%.17g %.17g\n", 2.0 * PI * a, b);
    else if (!strcmp(argv[0], "sphere") && argc == 2)
        printf("%.17g %.17g\n", 2.0 * PI * a, PI * a);
    else
        return 2;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 6 && !strcmp(argv[1], "exr"))
        return exr(argv + 2);
    if (argc == 14 && !strcmp(argv[1], "normal"))
        return normal(argv + 2);
    if (argc >= 4 && !strcmp(argv[1], "extent"))
        return extent(argc - 2, argv + 2);
    fprintf(stderr, "usage: height_check exr EXR PNG MIN_CM MAX_CM\n"
                    "       height_check normal NORMAL HEIGHT MIN_CM MAX_CM SCALE EXTENT_X EXTENT_Y WRAP_U WRAP_V "
                    "opengl|directx MAX_DEG MEAN_DEG\n"
                    "       height_check extent plane W H | cylinder R H | sphere R\n");
    return 2;
}
