/* Writing a lifted render mesh as a Wavefront OBJ file. */
#include "io/obj.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"

/* design: numbers are printed in fixed point by integer arithmetic (printf's %g costs more than
 * the lift itself on a large mesh): positions with enough decimals to resolve a hundredth of the weld
 * tolerance, so distinct positions stay distinct when read back, texture coordinates with 8 (float
 * precision near 1), normals with 6; trailing zeros are dropped. Rounding is llround's, half away
 * from zero, the same on every machine. */
typedef struct {
    FILE *f;
    char *buf;
    size_t n, cap;
} writer;

static void flush(writer *w)
{
    fwrite(w->buf, 1, w->n, w->f);
    w->n = 0;
}

static void put_char(writer *w, char c)
{
    if (w->n == w->cap)
        flush(w);
    w->buf[w->n++] = c;
}

static void put_text(writer *w, const char *s)
{
    for (; *s; s++)
        put_char(w, *s);
}

static void put_uint(writer *w, unsigned long long v)
{
    char digits[24];
    int n = 0;
    do {
        digits[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (n)
        put_char(w, digits[--n]);
}

static void put_fixed(writer *w, double x, int decimals)
{
    static const double scale[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12};
    long long v = llround(x * scale[decimals]);
    if (v < 0) {
        put_char(w, '-');
        v = -v;
    }
    unsigned long long p = (unsigned long long)scale[decimals];
    put_uint(w, (unsigned long long)v / p);
    unsigned long long frac = (unsigned long long)v % p;
    if (frac == 0)
        return;
    put_char(w, '.');
    int d = decimals;
    while (frac % 10 == 0) {
        frac /= 10;
        d--;
    }
    char digits[16];
    for (int i = d - 1; i >= 0; i--) {
        digits[i] = (char)('0' + frac % 10);
        frac /= 10;
    }
    for (int i = 0; i < d; i++)
        put_char(w, digits[i]);
}

static void put_group(writer *w, const fs_lifted_mesh *m, const char *group, int wall)
{
    bool any = false;
    for (int32_t t = 0; t < m->n_tris; t++) {
        if ((m->wall[t] != 0) != (wall != 0))
            continue;
        if (!any) {
            put_text(w, "g ");
            put_text(w, group);
            put_char(w, '\n');
        }
        any = true;
        const int32_t *c = m->corner + 9 * (size_t)t;
        put_char(w, 'f');
        for (int k = 0; k < 3; k++) {
            put_char(w, ' ');
            put_uint(w, (unsigned long long)c[3 * k] + 1);
            put_char(w, '/');
            put_uint(w, (unsigned long long)c[3 * k + 1] + 1);
            put_char(w, '/');
            put_uint(w, (unsigned long long)c[3 * k + 2] + 1);
        }
        put_char(w, '\n');
    }
}

int fs_obj_write(const char *path, const fs_lifted_mesh *m, const char *name, const char *comment, const char *mtllib)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot create the mesh file: %s", path, strerror(errno));
        return -1;
    }
    int32_t walls = 0;
    double extent = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        walls += m->wall[t] != 0;
    for (size_t i = 0; i < 3 * (size_t)m->n_pos; i++)
        extent = fmax(extent, fabs(m->pos[i]));
    int decimals = 0;
    while (decimals < 12 && (m->weld_tolerance <= 0.0 || pow(10.0, -decimals) > 0.01 * m->weld_tolerance))
        decimals++;
    while (decimals > 0 && extent * pow(10.0, decimals) > 1e17)
        decimals--;
    if (comment)
        fprintf(f, "# %s\n", comment);
    fprintf(f, "# units: cm; texture v runs up the maps; faces counter-clockwise seen from outside\n"
               "# %d positions, %d texture vertices, %d normals, %d triangles (%d in walls)\n",
            (int)m->n_pos, (int)m->n_uv, (int)m->n_normal, (int)m->n_tris, (int)walls);
    if (mtllib)
        fprintf(f, "mtllib %s\n", mtllib);
    fprintf(f, "o %s\n", name);
    if (mtllib)
        fprintf(f, "usemtl %s\n", name);
    fflush(f);
    writer w = {f, fs_malloc((size_t)1 << 16), 0, (size_t)1 << 16};
    for (int32_t i = 0; i < m->n_pos; i++) {
        put_char(&w, 'v');
        for (int q = 0; q < 3; q++) {
            put_char(&w, ' ');
            put_fixed(&w, m->pos[3 * (size_t)i + q], decimals);
        }
        put_char(&w, '\n');
    }
    for (int32_t i = 0; i < m->n_uv; i++) {
        put_text(&w, "vt ");
        put_fixed(&w, m->uv[2 * (size_t)i], 8);
        put_char(&w, ' ');
        put_fixed(&w, m->uv[2 * (size_t)i + 1], 8);
        put_char(&w, '\n');
    }
    for (int32_t i = 0; i < m->n_normal; i++) {
        put_text(&w, "vn");
        for (int q = 0; q < 3; q++) {
            put_char(&w, ' ');
            put_fixed(&w, m->normal[3 * (size_t)i + q], 6);
        }
        put_char(&w, '\n');
    }
    put_group(&w, m, "layer", 0);
    put_group(&w, m, "walls", 1);
    flush(&w);
    free(w.buf);
    return fs_close_written(f, path, "the mesh file");
}
