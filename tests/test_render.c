/* Tests of the OSMesa rasteriser and the texture maps (render/render.h). */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "check.h"

/* An axis-aligned quad [u0,u1] x [v0,v1] with constant attributes. */
static void add_quad(fs_surface *m, double u0, double v0, double u1, double v1, double height, double crack,
                     double cell, double shade)
{
    int32_t a = fs_surface_add_vertex(m, u0, v0, height, crack, cell, shade);
    int32_t b = fs_surface_add_vertex(m, u1, v0, height, crack, cell, shade);
    int32_t c = fs_surface_add_vertex(m, u1, v1, height, crack, cell, shade);
    int32_t d = fs_surface_add_vertex(m, u0, v1, height, crack, cell, shade);
    fs_surface_add_tri(m, a, b, c);
    fs_surface_add_tri(m, a, c, d);
}

static double mean(const float *x, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; k++)
        s += x[k];
    return s / (double)n;
}

/* Pixel of raster r at column i and row j (from the top). */
static size_t at(const fs_raster *r, int i, int j)
{
    return (size_t)j * (size_t)r->width + (size_t)i;
}

/* The triangle (0,0) (1,0) (1,1) covers half the square below the diagonal v = u: its area comes
 * out as half the map within one pixel row's worth (1/W), and it lies at the bottom right of the
 * image because v grows towards the top. Undrawn pixels are background: height 0, crack 1. */
static void test_half_square(void)
{
    const int W = 64;
    const double h = 2.5;
    fs_surface m = {0};
    int32_t a = fs_surface_add_vertex(&m, 0, 0, h, 0, 7, 0);
    int32_t b = fs_surface_add_vertex(&m, 1, 0, h, 0, 7, 0);
    int32_t c = fs_surface_add_vertex(&m, 1, 1, h, 0, 7, 0);
    fs_surface_add_tri(&m, a, b, c);
    fs_raster r;
    CHECK_MSG(fs_render_raster(&m, W, W, 4, false, false, &r) == 0, "%s", fs_error_message());
    size_t n = (size_t)W * W;
    CHECK_NEAR(mean(r.height_cm, n), h * 0.5, h / W);
    CHECK_NEAR(mean(r.crack, n), 0.5, 1.0 / W);
    CHECK(r.height_cm[at(&r, W - 1, W - 1)] == (float)h && r.cell[at(&r, W - 1, W - 1)] == 7);
    CHECK(r.height_cm[at(&r, 0, 0)] == 0.0f && r.crack[at(&r, 0, 0)] == 1.0f && r.cell[at(&r, 0, 0)] == 0);
    /* Pixels on the diagonal are partly covered: their coverage is about one half. */
    CHECK_NEAR(r.height_cm[at(&r, 10, W - 1 - 10)], h * 0.5, h * 0.25);
    fs_raster_free(&r);
    fs_surface_free(&m);
}

/* A quad at constant height gives exactly that height (and exact crack, cell and negative shade)
 * in its interior, and leaves everything outside untouched. */
static void test_quad_exact(void)
{
    const int W = 40, H = 24;
    const float h = 1.2345678f;
    fs_surface m = {0};
    add_quad(&m, 0.25, 0.25, 0.75, 0.75, h, 0.0, 4321, -0.75);
    fs_raster r;
    CHECK(fs_render_raster(&m, W, H, 3, false, false, &r) == 0);
    CHECK(r.width == W && r.height == H);
    int inside = 0, bad = 0;
    for (int j = 0; j < H; j++) {
        for (int i = 0; i < W; i++) {
            size_t k = at(&r, i, j);
            bool in = i >= W / 4 && i < 3 * W / 4 && j >= H / 4 && j < 3 * H / 4;
            bool out = i < W / 4 || i >= 3 * W / 4 || j < H / 4 || j >= 3 * H / 4;
            if (in) {
                inside++;
                bad += r.height_cm[k] != h || r.crack[k] != 0.0f || r.cell[k] != 4321 || r.shade[k] != -0.75f;
            } else if (out) {
                bad += r.height_cm[k] != 0.0f || r.crack[k] != 1.0f || r.cell[k] != 0 || r.shade[k] != 0.0f;
            }
        }
    }
    CHECK(inside == (W / 2) * (H / 2));
    CHECK_MSG(bad == 0, "%d pixels differ", bad);
    fs_raster_free(&r);
    fs_surface_free(&m);
}

/* Where triangles overlap, the higher one is seen, whichever is drawn first. */
static void test_depth(void)
{
    for (int order = 0; order < 2; order++) {
        fs_surface m = {0};
        if (order == 0) {
            add_quad(&m, 0, 0, 1, 1, 1.0, 0, 1, 0);
            add_quad(&m, 0.25, 0.25, 0.75, 0.75, 1.001, 1, 2, 0);
        } else {
            add_quad(&m, 0.25, 0.25, 0.75, 0.75, 1.001, 1, 2, 0);
            add_quad(&m, 0, 0, 1, 1, 1.0, 0, 1, 0);
        }
        fs_raster r;
        CHECK(fs_render_raster(&m, 32, 32, 2, false, false, &r) == 0);
        CHECK(r.cell[at(&r, 16, 16)] == 2 && r.height_cm[at(&r, 16, 16)] == 1.001f && r.crack[at(&r, 16, 16)] == 1.0f);
        CHECK(r.cell[at(&r, 2, 2)] == 1 && r.height_cm[at(&r, 2, 2)] == 1.0f && r.crack[at(&r, 2, 2)] == 0.0f);
        fs_raster_free(&r);
        fs_surface_free(&m);
    }
}

/* A sloped quad straddling u = 1 is drawn on both sides when u wraps: the columns at the left edge
 * continue the slope of the right edge, and the covered area is the whole quad. Without wrapping
 * only the part inside [0, 1] appears. The same holds for v across v = 0. */
static void test_wrap(void)
{
    const int W = 50, H = 20;
    fs_surface m = {0};
    /* Height 10 (u - 0.9) over u in [0.9, 1.1], v in [0.25, 0.75]. */
    int32_t a = fs_surface_add_vertex(&m, 0.9, 0.25, 0.0, 0, 3, 0);
    int32_t b = fs_surface_add_vertex(&m, 1.1, 0.25, 2.0, 0, 3, 0);
    int32_t c = fs_surface_add_vertex(&m, 1.1, 0.75, 2.0, 0, 3, 0);
    int32_t d = fs_surface_add_vertex(&m, 0.9, 0.75, 0.0, 0, 3, 0);
    fs_surface_add_tri(&m, a, b, c);
    fs_surface_add_tri(&m, a, c, d);
    fs_raster r;
    CHECK(fs_render_raster(&m, W, H, 4, true, false, &r) == 0);
    const int j = H / 2;
    double step = 10.0 / W;
    CHECK_NEAR(r.height_cm[at(&r, 0, j)] - r.height_cm[at(&r, W - 1, j)], step, 1e-4);
    CHECK_NEAR(r.height_cm[at(&r, W - 1, j)] - r.height_cm[at(&r, W - 2, j)], step, 1e-4);
    CHECK_NEAR(r.height_cm[at(&r, 1, j)] - r.height_cm[at(&r, 0, j)], step, 1e-4);
    CHECK(r.cell[at(&r, 0, j)] == 3 && r.cell[at(&r, W - 1, j)] == 3);
    CHECK_NEAR(1.0 - mean(r.crack, (size_t)W * H), 0.2 * 0.5, 1.0 / H);
    fs_raster_free(&r);

    CHECK(fs_render_raster(&m, W, H, 4, false, false, &r) == 0);
    CHECK(r.cell[at(&r, 0, j)] == 0 && r.cell[at(&r, W - 1, j)] == 3);
    CHECK_NEAR(1.0 - mean(r.crack, (size_t)W * H), 0.1 * 0.5, 1.0 / H);
    fs_raster_free(&r);
    fs_surface_free(&m);

    /* Across v = 0: the quad v in [-0.1, 0.1] appears in the bottom and the top rows. */
    add_quad(&m, 0.4, -0.1, 0.6, 0.1, 1.0, 0, 9, 0);
    CHECK(fs_render_raster(&m, W, H, 4, false, true, &r) == 0);
    CHECK(r.cell[at(&r, W / 2, 0)] == 9 && r.cell[at(&r, W / 2, H - 1)] == 9);
    CHECK(r.cell[at(&r, W / 2, H / 2)] == 0);
    fs_raster_free(&r);
    fs_surface_free(&m);
}

/* Cell ids come out as exact integers over the whole 16-bit range (each pixel its own quad). */
static void test_cell_ids(void)
{
    const int W = 64;
    fs_surface m = {0};
    for (int j = 0; j < W; j++)
        for (int i = 0; i < W; i++) {
            double cell = 65535 - 16 * (j * W + i);
            add_quad(&m, (double)i / W, 1.0 - (double)(j + 1) / W, (double)(i + 1) / W, 1.0 - (double)j / W, 1.0,
                     0, cell, 0);
        }
    fs_raster r;
    CHECK(fs_render_raster(&m, W, W, 4, false, false, &r) == 0);
    int bad = 0;
    for (int j = 0; j < W; j++)
        for (int i = 0; i < W; i++)
            bad += r.cell[at(&r, i, j)] != 65535 - 16 * (j * W + i);
    CHECK_MSG(bad == 0, "%d cell ids differ", bad);
    CHECK(r.cell[0] == 65535);
    fs_raster_free(&r);
    fs_surface_free(&m);
}

/* Random overlapping triangles at several heights, on both wrapping axes. With constant
 * attributes per triangle every sample is the same whichever tile holds it, so a render through
 * small tiles (10 x 10 pixels, ragged at the edges) is bit-identical to a single-tile render. With
 * sloped triangles only float rounding of interpolated values may differ. */
static void random_mesh(fs_surface *m, bool sloped)
{
    for (int t = 0; t < 400; t++) {
        double cu = fs_rand01(1, FS_RNG_TEST, 10 * t);
        double cv = fs_rand01(1, FS_RNG_TEST, 10 * t + 1);
        double h = 0.5 + floor(fs_rand01(1, FS_RNG_TEST, 10 * t + 2) * 64.0) / 16.0;
        int32_t v[3];
        for (int c = 0; c < 3; c++) {
            double du = (fs_rand01(1, FS_RNG_TEST, 10 * t + 3 + 2 * c) - 0.5) * 0.2;
            double dv = (fs_rand01(1, FS_RNG_TEST, 10 * t + 4 + 2 * c) - 0.5) * 0.2;
            double hv = sloped ? h + 0.3 * c : h;
            v[c] = fs_surface_add_vertex(m, cu + du, cv + dv, hv, t % 2, 1 + t, (t % 5) * 0.25 - 0.5);
        }
        fs_surface_add_tri(m, v[0], v[1], v[2]);
    }
}

static void compare_tilings(bool sloped, double tol)
{
    const int W = 96, H = 80;
    fs_surface m = {0};
    random_mesh(&m, sloped);
    fs_raster one, many;
    CHECK(fs_render_raster_tiled(&m, W, H, 4, true, true, 4096, &one) == 0);
    CHECK(fs_render_raster_tiled(&m, W, H, 4, true, true, 40, &many) == 0);
    size_t n = (size_t)W * H;
    double worst = 0.0;
    int cells = 0;
    for (size_t k = 0; k < n; k++) {
        worst = fmax(worst, fabs((double)one.height_cm[k] - many.height_cm[k]));
        worst = fmax(worst, fabs((double)one.crack[k] - many.crack[k]));
        worst = fmax(worst, fabs((double)one.shade[k] - many.shade[k]));
        cells += one.cell[k] != many.cell[k];
    }
    CHECK_MSG(worst <= tol, "largest difference %g", worst);
    CHECK(cells == 0);
    /* The mesh is not trivial: both drawn and undrawn pixels exist. */
    CHECK(mean(one.crack, n) > 0.05 && mean(one.crack, n) < 0.95);
    fs_raster_free(&one);
    fs_raster_free(&many);
    fs_surface_free(&m);
}

static void test_tiling(void)
{
    compare_tilings(false, 0.0);
    compare_tilings(true, 1e-5);
}

/* A raster with given height field (function of column and row) and no cracks. */
static void make_raster(fs_raster *r, int w, int h)
{
    size_t n = (size_t)w * h;
    r->width = w;
    r->height = h;
    r->height_cm = calloc(n, sizeof(float));
    r->crack = calloc(n, sizeof(float));
    r->shade = calloc(n, sizeof(float));
    r->cell = calloc(n, sizeof(uint16_t));
}

static uint8_t expect_u8(double x)
{
    return (uint8_t)floor(x * 255.0 + 0.5);
}

/* A height ramp gives one constant normal everywhere (the clamped border differences see the same
 * slope). Rising by 0.25 cm per row towards the top with 0.5 cm pixels is a slope of 0.5 along +v:
 * the surface faces down the image, n = (0, -0.5, 1) / |.|, so OpenGL green is below 128 and
 * DirectX green is its bitwise inverse 255 - g; height_scale 2 doubles the slope. A ramp rising to the right faces
 * left: red below 128. */
static void test_normal_ramp(void)
{
    const int W = 12, H = 10;
    fs_render_params p = fs_render_params_default();
    for (int axis = 0; axis < 2; axis++) {
        for (int conv = 0; conv < 2; conv++) {
            for (int scale = 1; scale <= 2; scale++) {
                fs_raster r = {0};
                make_raster(&r, W, H);
                for (int j = 0; j < H; j++)
                    for (int i = 0; i < W; i++)
                        r.height_cm[j * W + i] = axis == 0 ? 0.25f * (float)(H - 1 - j) : 0.25f * (float)i;
                p.normal = conv ? FS_NORMAL_DIRECTX : FS_NORMAL_OPENGL;
                p.height_scale = scale;
                fs_maps maps;
                CHECK(fs_maps_build(&r, &p, false, false, 0.5, 0.5, &maps) == 0);
                double g = -0.5 * scale, len = sqrt(g * g + 1.0);
                double nx = axis == 0 ? 0.0 : g / len, ny = axis == 0 ? g / len : 0.0, nz = 1.0 / len;
                uint8_t green = expect_u8(ny * 0.5 + 0.5);
                uint8_t want[3] = {expect_u8(nx * 0.5 + 0.5), (uint8_t)(conv ? 255 - green : green),
                                   expect_u8(nz * 0.5 + 0.5)};
                const uint8_t *px = maps.normal.data;
                int bad = 0;
                for (int k = 0; k < W * H; k++)
                    bad += px[3 * k] != want[0] || px[3 * k + 1] != want[1] || px[3 * k + 2] != want[2];
                CHECK_MSG(bad == 0, "axis %d conv %d scale %d: %d pixels differ", axis, conv, scale, bad);
                if (axis == 0)
                    CHECK(conv ? px[1] > 128 : px[1] < 128);
                else
                    CHECK(px[0] < 128 && px[1] == (conv ? 127 : 128));
                fs_maps_free(&maps);
                fs_raster_free(&r);
            }
        }
    }
}

/* The height map spans 0..65535 from the lowest to the highest point and records the range. */
static void test_height_map(void)
{
    fs_raster r = {0};
    make_raster(&r, 4, 1);
    r.height_cm[0] = 0.5f;
    r.height_cm[1] = 1.0f;
    r.height_cm[2] = 2.5f;
    r.height_cm[3] = 1.5f;
    fs_render_params p = fs_render_params_default();
    fs_maps maps;
    CHECK(fs_maps_build(&r, &p, false, false, 1.0, 1.0, &maps) == 0);
    const uint16_t *h = maps.height.data;
    CHECK(h[0] == 0 && h[2] == 65535 && h[3] == 32768 && h[1] == 16384);
    CHECK_NEAR(maps.height_min_cm, 0.5, 1e-12);
    CHECK_NEAR(maps.height_max_cm, 2.5, 1e-12);
    CHECK(maps.height.type == FS_PIX_U16 && maps.height.channels == 1);
    fs_maps_free(&maps);
    fs_raster_free(&r);
}

/* A vertical crack line in column 10: the mask is white there, the distance is 0 on it and grows
 * by crackdist_scale per pixel away from it, the short way round when u wraps; cell ids pass
 * through. */
static void test_crack_maps(void)
{
    const int W = 40, H = 6;
    fs_raster r = {0};
    make_raster(&r, W, H);
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
            r.crack[j * W + i] = i == 10 ? 1.0f : i == 11 ? 0.25f : 0.0f;
            r.cell[j * W + i] = i == 10 ? 0 : i < 10 ? 5 : 6;
            r.height_cm[j * W + i] = i == 10 ? 0.0f : 1.0f;
        }
    fs_render_params p = fs_render_params_default();
    for (int wrap = 0; wrap < 2; wrap++) {
        fs_maps maps;
        CHECK(fs_maps_build(&r, &p, wrap, false, 1.0, 1.0, &maps) == 0);
        const uint8_t *mask = maps.crackmask.data;
        const uint16_t *dist = maps.crackdist.data, *cell = maps.cellid.data;
        CHECK(mask[10] == 255 && mask[11] == 64 && mask[12] == 0);
        CHECK(dist[10] == 0 && dist[2 * W + 10] == 0);
        CHECK(dist[13] == (uint16_t)(3 * maps.crackdist_scale));
        int increasing = 1;
        for (int i = 11; i < 25; i++)
            increasing &= dist[i + 1] > dist[i];
        CHECK(increasing);
        CHECK(dist[W - 1] == (uint16_t)((wrap ? 11 : 29) * maps.crackdist_scale));
        CHECK(cell[10] == 0 && cell[3] == 5 && cell[30] == 6);
        fs_maps_free(&maps);
    }
    fs_raster_free(&r);
}

static double srgb(double c)
{
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

/* Basecolor: the top of a cell with shade 0 is the material colour, a crack wall half-way down is
 * the crack colour, the bottom is the background colour (all sRGB-encoded); positive shade makes
 * a cell lighter. In the default palette material > crack > background in brightness. */
static void test_basecolor(void)
{
    fs_raster r = {0};
    make_raster(&r, 4, 1);
    r.height_cm[0] = 2.0f;
    r.height_cm[1] = 1.0f;
    r.crack[1] = 1.0f;
    r.height_cm[2] = 0.0f;
    r.crack[2] = 1.0f;
    r.height_cm[3] = 2.0f;
    r.shade[3] = 1.0f;
    fs_render_params p = fs_render_params_default();
    fs_maps maps;
    CHECK(fs_maps_build(&r, &p, false, false, 1.0, 1.0, &maps) == 0);
    const uint8_t *c = maps.basecolor.data;
    int bad = 0;
    for (int k = 0; k < 3; k++) {
        bad += c[k] != expect_u8(srgb(p.color_material[k]));
        bad += c[3 + k] != expect_u8(srgb(p.color_crack[k]));
        bad += c[6 + k] != expect_u8(srgb(p.color_background[k]));
        bad += c[9 + k] <= c[k];
    }
    CHECK_MSG(bad == 0, "%d channels differ", bad);
    CHECK(c[0] + c[1] + c[2] > c[3] + c[4] + c[5] && c[3] + c[4] + c[5] > c[6] + c[7] + c[8]);
    fs_maps_free(&maps);
    fs_raster_free(&r);
}

int main(void)
{
    RUN(test_half_square);
    RUN(test_quad_exact);
    RUN(test_depth);
    RUN(test_wrap);
    RUN(test_cell_ids);
    RUN(test_tiling);
    RUN(test_normal_ramp);
    RUN(test_height_map);
    RUN(test_crack_maps);
    RUN(test_basecolor);
    return check_finish();
}
