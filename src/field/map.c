/* Grey-level maps: bilinear sampling that wraps or clamps per axis. */
#include "field/map.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Pixel index along one axis: wrapped or clamped. */
static int map_index(int i, int n, bool wrap)
{
    if (wrap) {
        i %= n;
        return i < 0 ? i + n : i;
    }
    return i < 0 ? 0 : i >= n ? n - 1 : i;
}

double fs_grey_map_sample(const fs_grey_map *m, double u, double v)
{
    if (!m->grey)
        return 1.0;
    double fx = u * m->width - 0.5, fy = (1.0 - v) * m->height - 0.5;
    double x0 = floor(fx), y0 = floor(fy);
    double ax = fx - x0, ay = fy - y0;
    int i0 = map_index((int)x0, m->width, m->wrap_u), i1 = map_index((int)x0 + 1, m->width, m->wrap_u);
    int j0 = map_index((int)y0, m->height, m->wrap_v), j1 = map_index((int)y0 + 1, m->height, m->wrap_v);
    const float *g = m->grey;
    double top = g[(size_t)j0 * m->width + i0] * (1.0 - ax) + g[(size_t)j0 * m->width + i1] * ax;
    double bot = g[(size_t)j1 * m->width + i0] * (1.0 - ax) + g[(size_t)j1 * m->width + i1] * ax;
    return top * (1.0 - ay) + bot * ay;
}

void fs_grey_map_free(fs_grey_map *m)
{
    free(m->grey);
    memset(m, 0, sizeof *m);
}
