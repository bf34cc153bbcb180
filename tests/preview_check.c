/* Test helper: does a preview image show a lit, shaded object filling the middle of the frame? */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "base/error.h"
#include "image/image.h"

/* Usage: preview_check FILE
 * The object is every pixel that differs from the backdrop, a smooth vertical gradient: from the
 * corner pixel of its own row by more than 12/255 in some channel. Checks, printing one line per
 * failure and a summary line:
 *  - the image is 8-bit RGB;
 *  - the object covers between 15% and 95% of the frame, and its centroid lies within 15% of the
 *    frame's size of the centre (the camera frames it);
 *  - the object is shaded, not flat: the luminance of its pixels spreads (standard deviation above
 *    0.06), and its 5th and 95th percentiles (cracks and shadows against lit tops) lie more than
 *    0.3 apart. */

static double luminance(const unsigned char *p)
{
    return (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: preview_check FILE\n");
        return 2;
    }
    fs_image img;
    if (fs_image_read(argv[1], &img) < 0) {
        fprintf(stderr, "preview_check: %s\n", fs_error_message());
        return 2;
    }
    int failures = 0;
    if (img.channels != 3 || img.type != FS_PIX_U8) {
        printf("FAIL %s is not 8-bit RGB\n", argv[1]);
        fs_image_free(&img);
        return 1;
    }
    const unsigned char *px = img.data;
    int w = img.width, h = img.height;
    long covered = 0, histogram[256] = {0};
    double sx = 0.0, sy = 0.0, sl = 0.0, sll = 0.0;
    for (int j = 0; j < h; j++) {
        const unsigned char *corner = px + 3 * (size_t)j * (size_t)w;
        for (int i = 0; i < w; i++) {
            const unsigned char *p = px + 3 * ((size_t)j * (size_t)w + (size_t)i);
            int diff = 0;
            for (int c = 0; c < 3; c++)
                diff = abs(p[c] - corner[c]) > diff ? abs(p[c] - corner[c]) : diff;
            if (diff <= 12)
                continue;
            covered++;
            sx += i + 0.5;
            sy += j + 0.5;
            double l = luminance(p);
            sl += l;
            sll += l * l;
            histogram[(int)floor(l * 255.0 + 0.5)]++;
        }
    }
    double frac = (double)covered / ((double)w * h);
    double cx = covered ? sx / covered / w : 0.0, cy = covered ? sy / covered / h : 0.0;
    double mean = covered ? sl / covered : 0.0, sd = covered ? sqrt(fmax(sll / covered - mean * mean, 0.0)) : 0.0;
    int p05 = 0, p95 = 255;
    long below = 0;
    for (int k = 0; k < 256; k++) {
        if (below < 0.05 * covered)
            p05 = k;
        below += histogram[k];
        if (below < 0.95 * covered)
            p95 = k + 1;
    }
    if (frac < 0.15 || frac > 0.95) {
        printf("FAIL the object covers %.3f of the frame, expected 0.15 to 0.95\n", frac);
        failures++;
    }
    if (fabs(cx - 0.5) > 0.15 || fabs(cy - 0.5) > 0.15) {
        printf("FAIL the object's centroid is at (%.3f, %.3f) of the frame, expected within 0.15 of the centre\n", cx,
               cy);
        failures++;
    }
    if (sd < 0.06) {
        printf("FAIL the object's luminance varies by %.4f (standard deviation), expected above 0.06\n", sd);
        failures++;
    }
    if ((p95 - p05) / 255.0 <= 0.3) {
        printf("FAIL the object's luminance percentiles 5 and 95 are %.3f and %.3f, expected more than 0.3 apart\n",
               p05 / 255.0, p95 / 255.0);
        failures++;
    }
    printf("%dx%d coverage=%.3f centroid=(%.3f,%.3f) luminance mean=%.3f sd=%.3f p05=%.3f p95=%.3f\n", w, h, frac, cx,
           cy, mean, sd, p05 / 255.0, p95 / 255.0);
    fs_image_free(&img);
    return failures ? 1 : 0;
}
