/* Test helper: does an image continue across its opposite edges as smoothly as it does beside them? */
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

/* Ratio of the seam difference (last line to first) to the larger of the differences of the line
 * pairs on either side of it (the last two lines, the first two). Across a seamless edge the image
 * changes as it does beside it: a crack lying along the seam shows in its neighbours' differences
 * too, where a mean over the whole image would take it for a seam; a picture that does not wrap
 * changes several times more across the edge than beside it. */
static double seam_ratio(const fs_image *img, int rows)
{
    int n = rows ? img->height : img->width;
    double beside = fmax(line_diff(img, rows, n - 2, n - 1), line_diff(img, rows, 0, 1));
    return line_diff(img, rows, n - 1, 0) / (beside > 1e-12 ? beside : 1e-12);
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
        printf("x seam/beside = %.3f ", r);
        ok &= r <= 1.5;
    }
    if (strchr(argv[1], 'y')) {
        double r = seam_ratio(&img, 1);
        printf("y seam/beside = %.3f ", r);
        ok &= r <= 1.5;
    }
    printf("\n");
    fs_image_free(&img);
    return ok ? 0 : 1;
}
