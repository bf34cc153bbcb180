/* Test helper: does an image continue across its opposite edges as smoothly as it does inside? */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/error.h"
#include "image/image.h"

static double sample(const fs_image *img, int x, int y, int c)
{
    size_t i = ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels + (size_t)c;
    switch (img->type) {
    case FS_PIX_U8: return ((const unsigned char *)img->data)[i] / 255.0;
    case FS_PIX_U16: return ((const unsigned short *)img->data)[i] / 65535.0;
    case FS_PIX_F32: return ((const float *)img->data)[i];
    }
    return 0;
}

/* Mean absolute difference between column x0 and column x1 (or rows, when rows != 0). */
static double line_diff(const fs_image *img, int rows, int a, int b)
{
    double sum = 0;
    int n = rows ? img->width : img->height;
    for (int k = 0; k < n; k++)
        for (int c = 0; c < img->channels; c++)
            sum += rows ? fabs(sample(img, k, a, c) - sample(img, k, b, c))
                        : fabs(sample(img, a, k, c) - sample(img, b, k, c));
    return sum / (n * img->channels);
}

/* Ratio of the seam difference to the mean difference of neighbouring lines inside. */
static double seam_ratio(const fs_image *img, int rows)
{
    int n = rows ? img->height : img->width;
    double inside = 0;
    for (int k = 0; k + 1 < n; k++)
        inside += line_diff(img, rows, k, k + 1);
    inside /= n - 1;
    return line_diff(img, rows, n - 1, 0) / (inside > 1e-12 ? inside : 1e-12);
}

int main(int argc, char **argv)
{
    if (argc != 3 || (strcmp(argv[1], "x") && strcmp(argv[1], "y") && strcmp(argv[1], "xy"))) {
        fprintf(stderr, "usage: tile_edges x|y|xy IMAGE\n");
        return 2;
    }
    fs_image img = {0};
    if (fs_image_read(argv[2], &img) < 0) {
        fprintf(stderr, "tile_edges: %s\n", fs_error_message());
        return 2;
    }
    int ok = 1;
    if (strchr(argv[1], 'x')) {
        double r = seam_ratio(&img, 0);
        printf("x seam/inside = %.3f ", r);
        ok &= r <= 1.5;
    }
    if (strchr(argv[1], 'y')) {
        double r = seam_ratio(&img, 1);
        printf("y seam/inside = %.3f ", r);
        ok &= r <= 1.5;
    }
    printf("\n");
    fs_image_free(&img);
    return ok ? 0 : 1;
}
