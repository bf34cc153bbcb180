/* Test helper: measures a crack mask or a crack graph, for the shell tests of the crack presets (orientation, density inside a map). */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/uf.h"
#include "base/vec.h"
#include "image/image.h"
#include "io/json.h"

/* A crack pixel: at least half white in the anti-aliased mask. */
#define CRACK 0.5f

static int usage(void)
{
    fprintf(stderr, "usage: crack_stats runs MASK.png [V0 V1 [U0 U1]]\n"
                    "       crack_stats inside MASK.png GREY.png LEVEL\n"
                    "       crack_stats crossings CELLID.png U0 U1\n"
                    "       crack_stats pieces MASK.png CELLID.png none|x|y|xy\n"
                    "       crack_stats directions CRACKS.json SPAN_U SPAN_V MIN_CHORD DEGREES\n");
    return 2;
}

static float *read_grey(const char *path, int *w, int *h)
{
    float *g = NULL;
    if (fs_image_read_grey(path, w, h, &g) < 0) {
        fprintf(stderr, "crack_stats: %s: %s\n", path, fs_error_message());
        return NULL;
    }
    return g;
}

/* Mean length (pixels) of the vertical and of the horizontal runs of crack pixels, over the rows
 * from V0 to V1 (fractions of the height from the top; the whole map by default) and the columns
 * from U0 to U1 (fractions of the width from the left). Horizontal runs wrap across the left and
 * right edges when the band spans the whole width; runs are cut at the ends of the band. Cracks that
 * run up and down the map give long vertical runs and short horizontal ones (their width); a pattern
 * without a direction gives runs of about the same length both ways. Prints "VERTICAL HORIZONTAL
 * CRACK_FRACTION COVERAGE": the last two are the fraction of crack pixels and the mean mask value
 * (anti-aliased, so it counts cracks thinner than a pixel) over the band. */
static int runs(int argc, char **argv)
{
    if (argc != 3 && argc != 5 && argc != 7)
        return usage();
    int w, h;
    float *g = read_grey(argv[2], &w, &h);
    if (!g)
        return 2;
    int y0 = 0, y1 = h, x0 = 0, x1 = w;
    if (argc >= 5) {
        y0 = (int)(atof(argv[3]) * h);
        y1 = (int)(atof(argv[4]) * h);
    }
    if (argc == 7) {
        x0 = (int)(atof(argv[5]) * w);
        x1 = (int)(atof(argv[6]) * w);
    }
    if (y0 < 0 || y1 > h || y0 >= y1 || x0 < 0 || x1 > w || x0 >= x1) {
        free(g);
        return usage();
    }
    bool wrap = x0 == 0 && x1 == w;
    long crack = 0, v_runs = 0, h_runs = 0;
    double coverage = 0.0;
    for (int x = x0; x < x1; x++) /* a vertical run starts where the pixel above is not a crack */
        for (int y = y0; y < y1; y++) {
            float c = g[(size_t)y * w + x];
            coverage += c;
            if (c >= CRACK) {
                crack++;
                v_runs += y == y0 || g[(size_t)(y - 1) * w + x] < CRACK;
            }
        }
    for (int y = y0; y < y1; y++) {
        const float *row = g + (size_t)y * w;
        bool full = true;
        for (int x = x0; x < x1; x++)
            if (row[x] >= CRACK) {
                if (x > x0)
                    h_runs += row[x - 1] < CRACK;
                else
                    h_runs += !wrap || row[w - 1] < CRACK;
            } else {
                full = false;
            }
        h_runs += wrap && full; /* a whole wrapped row of crack is one run */
    }
    free(g);
    double area = (double)(x1 - x0) * (y1 - y0);
    printf("%.3f %.3f %.5f %.5f\n", v_runs ? (double)crack / v_runs : 0.0, h_runs ? (double)crack / h_runs : 0.0,
           crack / area, coverage / area);
    return 0;
}

/* Mean crack coverage of the mask (its anti-aliased value, so cracks thinner than a pixel count
 * too) where GREY, resampled to the mask's size (nearest pixel), is below LEVEL and where it is
 * not. Prints "INSIDE OUTSIDE". */
static int inside(int argc, char **argv)
{
    if (argc != 5)
        return usage();
    int w, h, gw, gh;
    float *m = read_grey(argv[2], &w, &h);
    if (!m)
        return 2;
    float *g = read_grey(argv[3], &gw, &gh);
    if (!g) {
        free(m);
        return 2;
    }
    double level = atof(argv[4]);
    long n_in = 0, n_out = 0;
    double c_in = 0.0, c_out = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int gx = (int)((x + 0.5) * gw / w), gy = (int)((y + 0.5) * gh / h);
            int is_in = g[(size_t)gy * gw + gx] < level;
            double c = m[(size_t)y * w + x];
            n_in += is_in;
            n_out += !is_in;
            c_in += is_in ? c : 0.0;
            c_out += is_in ? 0.0 : c;
        }
    free(m);
    free(g);
    printf("%.5f %.5f\n", n_in ? c_in / n_in : 0.0, n_out ? c_out / n_out : 0.0);
    return 0;
}

/* Crack density of a fragment-id map (NAME_cellid.png, 0 = crack) over the columns from U0 to U1:
 * walking along each row and each column of the band, the number of times the fragment changes
 * (crack pixels skipped), per 100 pixels walked. Unlike the mask's coverage this counts cracks, not
 * how wide they open. Prints "ALONG_ROWS ALONG_COLUMNS". */
static int crossings(int argc, char **argv)
{
    if (argc != 5)
        return usage();
    int w, h;
    float *g = read_grey(argv[2], &w, &h);
    if (!g)
        return 2;
    int x0 = (int)(atof(argv[3]) * w), x1 = (int)(atof(argv[4]) * w);
    if (x0 < 0 || x1 > w || x0 >= x1) {
        free(g);
        return usage();
    }
    long rows = 0, cols = 0;
    for (int y = 0; y < h; y++) {
        float last = 0.0f;
        for (int x = x0; x < x1; x++) {
            float id = g[(size_t)y * w + x];
            if (id == 0.0f)
                continue;
            rows += last != 0.0f && id != last;
            last = id;
        }
    }
    for (int x = x0; x < x1; x++) {
        float last = 0.0f;
        for (int y = 0; y < h; y++) {
            float id = g[(size_t)y * w + x];
            if (id == 0.0f)
                continue;
            cols += last != 0.0f && id != last;
            last = id;
        }
    }
    free(g);
    double walked = (double)(x1 - x0) * h;
    printf("%.3f %.3f\n", 100.0 * rows / walked, 100.0 * cols / walked);
    return 0;
}

/* The share of the crack graph's length that runs within DEGREES of the v direction (a trunk's
 * axis): each polyline counts by its chord, from its first point to its last, in centimetres (the
 * texture's spans SPAN_U x SPAN_V); chords shorter than MIN_CHORD (the element-scale wiggle of
 * short branches) are left out. Prints "SHARE CHORDS LENGTH". */
static int directions(int argc, char **argv)
{
    if (argc != 7)
        return usage();
    double span[2] = {atof(argv[3]), atof(argv[4])}, min_chord = atof(argv[5]), degrees = atof(argv[6]);
    fs_json *root = fs_json_read(argv[2]);
    if (!root) {
        fprintf(stderr, "crack_stats: %s: %s\n", argv[2], fs_error_message());
        return 1;
    }
    fs_json *cracks = fs_json_get(root, "cracks");
    double total = 0.0, within = 0.0;
    long chords = 0;
    for (size_t c = 0; c < fs_json_size(cracks); c++) {
        fs_json *lines = fs_json_get(fs_json_at(cracks, c), "polylines");
        for (size_t l = 0; l < fs_json_size(lines); l++) {
            fs_json *line = fs_json_at(lines, l);
            size_t n = fs_json_size(line);
            if (n < 2)
                continue;
            double d[2];
            for (int k = 0; k < 2; k++)
                d[k] = (fs_json_number(fs_json_at(fs_json_at(line, n - 1), (size_t)k)) -
                        fs_json_number(fs_json_at(fs_json_at(line, 0), (size_t)k))) * span[k];
            double len = hypot(d[0], d[1]);
            if (len < min_chord)
                continue;
            chords++;
            total += len;
            if (atan2(fabs(d[0]), fabs(d[1])) <= degrees * FS_PI / 180.0)
                within += len;
        }
    }
    fs_json_free(root);
    printf("%.4f %ld %.3f\n", total > 0.0 ? within / total : 0.0, chords, total);
    return 0;
}

static int compare_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Whether the fragments stand apart in the crack mask: the 4-connected pieces of the pixels under
 * half intensity (the mask's solid ground; wrapping across the periodic axes given), against the
 * fragments in the cell-id map (its distinct non-zero ids, the model's fragments that show). Prints
 * "PIECES FRAGMENTS JOINED COVERAGE": JOINED counts the pieces that hold pixels of more than one
 * fragment (a crack too narrow to separate them at half intensity), COVERAGE is the mean mask
 * value. A piece may hold part of a fragment only (an open crack that nearly cuts it through). */
static int pieces(int argc, char **argv)
{
    if (argc != 5 || (strcmp(argv[4], "none") && strcmp(argv[4], "x") && strcmp(argv[4], "y") &&
                      strcmp(argv[4], "xy")))
        return usage();
    int w, h, cw, ch;
    float *m = read_grey(argv[2], &w, &h);
    if (!m)
        return 2;
    float *c = read_grey(argv[3], &cw, &ch);
    if (!c || cw != w || ch != h) {
        if (c)
            fprintf(stderr, "crack_stats: %s is %dx%d, %s %dx%d\n", argv[3], cw, ch, argv[2], w, h);
        free(m);
        free(c);
        return 2;
    }
    bool wrap_x = strchr(argv[4], 'x') != NULL, wrap_y = strchr(argv[4], 'y') != NULL;
    int32_t n = (int32_t)w * h;
    int32_t *parent = malloc((size_t)n * sizeof *parent);
    float *ids = malloc((size_t)n * sizeof *ids);
    if (!parent || !ids) {
        fprintf(stderr, "crack_stats: out of memory\n");
        return 2;
    }
    fs_uf_init(parent, n);
    double coverage = 0.0;
    int32_t n_ids = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int32_t i = (int32_t)y * w + x;
            coverage += m[i];
            if (c[i] > 0.0f)
                ids[n_ids++] = c[i];
            if (m[i] >= CRACK)
                continue;
            int32_t right = x + 1 < w ? i + 1 : wrap_x ? i + 1 - w : -1;
            int32_t down = y + 1 < h ? i + w : wrap_y ? x : -1;
            if (right >= 0 && m[right] < CRACK)
                fs_uf_union(parent, i, right);
            if (down >= 0 && m[down] < CRACK)
                fs_uf_union(parent, i, down);
        }
    long count = 0, joined = 0;
    float *first = calloc((size_t)n, sizeof *first); /* per root: the first fragment id seen in it */
    uint8_t *mixed = calloc((size_t)n, 1);
    if (!first || !mixed) {
        fprintf(stderr, "crack_stats: out of memory\n");
        return 2;
    }
    for (int32_t i = 0; i < n; i++) {
        if (m[i] >= CRACK)
            continue;
        int32_t r = fs_uf_find(parent, i);
        count += r == i;
        if (c[i] > 0.0f) {
            if (first[r] == 0.0f)
                first[r] = c[i];
            else if (first[r] != c[i] && !mixed[r]) {
                mixed[r] = 1;
                joined++;
            }
        }
    }
    free(first);
    free(mixed);
    qsort(ids, (size_t)n_ids, sizeof *ids, compare_float);
    long fragments = 0;
    for (int32_t k = 0; k < n_ids; k++)
        fragments += k == 0 || ids[k] != ids[k - 1];
    printf("%ld %ld %ld %.5f\n", count, fragments, joined, coverage / n);
    free(parent);
    free(ids);
    free(m);
    free(c);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage();
    if (!strcmp(argv[1], "runs"))
        return runs(argc, argv);
    if (!strcmp(argv[1], "directions"))
        return directions(argc, argv);
    if (!strcmp(argv[1], "inside"))
        return inside(argc, argv);
    if (!strcmp(argv[1], "crossings"))
        return crossings(argc, argv);
    if (!strcmp(argv[1], "pieces"))
        return pieces(argc, argv);
    return usage();
}
