/* Tests of image I/O, comparison, distance transform and downsampling (image/image.h). */
#include "image/image.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "check.h"

static char tmpdir[] = "/tmp/fissure-test-image-XXXXXX";

static const char *tmp_path(const char *name)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    return path;
}

/* A deterministic pattern that exercises every bit of each sample. */
static uint32_t pattern(size_t k)
{
    uint32_t x = (uint32_t)k * 2654435761u + 12345u;
    x ^= x >> 15;
    x *= 2246822519u;
    return x ^ (x >> 13);
}

static void roundtrip(int channels, fs_pixel_type type, const char *name)
{
    fs_image a, b = {0};
    fs_image_alloc(&a, 37, 23, channels, type);
    size_t n = (size_t)a.width * a.height * channels;
    for (size_t k = 0; k < n; k++) {
        if (type == FS_PIX_U8)
            ((uint8_t *)a.data)[k] = (uint8_t)pattern(k);
        else if (type == FS_PIX_U16)
            ((uint16_t *)a.data)[k] = (uint16_t)pattern(k);
        else
            ((float *)a.data)[k] = (float)((double)pattern(k) / 4294967296.0 * 200.0 - 50.0);
    }
    CHECK_MSG(fs_image_write(tmp_path(name), &a) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_image_read(tmp_path(name), &b) == 0, "%s", fs_error_message());
    CHECK(b.width == a.width && b.height == a.height && b.channels == channels && b.type == type);
    if (b.data && b.width == a.width && b.height == a.height && b.channels == channels && b.type == type) {
        if (type == FS_PIX_F32) {
            double worst = 0.0;
            for (size_t k = 0; k < n; k++)
                worst = fmax(worst, fabs((double)((float *)a.data)[k] - ((float *)b.data)[k]));
            CHECK_NEAR(worst, 0.0, 1e-6);
        } else {
            CHECK(memcmp(a.data, b.data, fs_image_bytes(&a)) == 0);
        }
    }
    fs_image_free(&a);
    fs_image_free(&b);
}

/* 8- and 16-bit PNG, grey and RGB, are lossless; EXR keeps 32-bit floats. */
static void test_roundtrip(void)
{
    roundtrip(1, FS_PIX_U8, "g8.png");
    roundtrip(3, FS_PIX_U8, "rgb8.png");
    roundtrip(1, FS_PIX_U16, "g16.png");
    roundtrip(3, FS_PIX_U16, "rgb16.png");
    roundtrip(1, FS_PIX_F32, "g.exr");
    roundtrip(3, FS_PIX_F32, "rgb.exr");
}

/* Channel order on disk is BGR (what every other reader expects): a pure red image read back as
 * grey averages to 1/3, and its first channel is red after reading. */
static void test_channel_order(void)
{
    fs_image a, b = {0};
    fs_image_alloc(&a, 4, 4, 3, FS_PIX_U8);
    for (int k = 0; k < 16; k++)
        ((uint8_t *)a.data)[3 * k] = 255;
    CHECK(fs_image_write(tmp_path("red.png"), &a) == 0);
    CHECK(fs_image_read(tmp_path("red.png"), &b) == 0);
    CHECK(b.data && ((uint8_t *)b.data)[0] == 255 && ((uint8_t *)b.data)[1] == 0 && ((uint8_t *)b.data)[2] == 0);
    int w = 0, h = 0;
    float *g = NULL;
    CHECK(fs_image_read_grey(tmp_path("red.png"), &w, &h, &g) == 0);
    CHECK(w == 4 && h == 4);
    if (g)
        CHECK_NEAR(g[5], 1.0 / 3.0, 1e-6);
    free(g);
    fs_image_free(&a);
    fs_image_free(&b);
}

/* Identical images: PSNR +inf, SSIM 1, max difference 0. */
static void test_compare_identical(void)
{
    fs_image a;
    fs_image_alloc(&a, 32, 24, 3, FS_PIX_U16);
    for (size_t k = 0; k < 32 * 24 * 3; k++)
        ((uint16_t *)a.data)[k] = (uint16_t)pattern(k);
    fs_image_diff d;
    CHECK(fs_image_compare(&a, &a, &d) == 0);
    CHECK(isinf(d.psnr) && d.psnr > 0);
    CHECK(d.ssim == 1.0);
    CHECK(d.max_diff == 0.0);
    fs_image_free(&a);
}

/* One pixel of a 64 x 48 grey image off by 51/255 = 0.2: MSE = 0.04 / 3072, so
 * PSNR = 10 log10(3072 / 0.04) dB, and the max difference is 0.2. Depths may differ: the same
 * image at 16 bits compares as identical. */
static void test_compare_known(void)
{
    fs_image a, b, c;
    fs_image_alloc(&a, 64, 48, 1, FS_PIX_U8);
    fs_image_alloc(&b, 64, 48, 1, FS_PIX_U8);
    fs_image_alloc(&c, 64, 48, 1, FS_PIX_U16);
    for (size_t k = 0; k < 64 * 48; k++) {
        uint8_t v = (uint8_t)(100 + (k % 7) * 10);
        ((uint8_t *)a.data)[k] = ((uint8_t *)b.data)[k] = v;
        ((uint16_t *)c.data)[k] = (uint16_t)(v * 257);
    }
    ((uint8_t *)b.data)[64 * 20 + 30] += 51;
    fs_image_diff d;
    CHECK(fs_image_compare(&a, &b, &d) == 0);
    CHECK_NEAR(d.psnr, 10.0 * log10(3072.0 / 0.04), 1e-9);
    CHECK_NEAR(d.max_diff, 0.2, 1e-12);
    CHECK(d.ssim < 1.0 && d.ssim > 0.9);
    CHECK(fs_image_compare(&a, &c, &d) == 0);
    CHECK(isinf(d.psnr));
    CHECK_NEAR(d.max_diff, 0.0, 1e-12);
    fs_image_free(&a);
    fs_image_free(&b);
    fs_image_free(&c);
}

/* Images of different sizes cannot be compared: -1 with FS_ERR_DATA. */
static void test_compare_mismatch(void)
{
    fs_image a, b;
    fs_image_alloc(&a, 8, 8, 1, FS_PIX_U8);
    fs_image_alloc(&b, 8, 9, 1, FS_PIX_U8);
    fs_image_diff d;
    fs_error_clear();
    CHECK(fs_image_compare(&a, &b, &d) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_image_free(&a);
    fs_image_free(&b);
}

/* The distance from a single marked pixel is the Euclidean distance, in pixels. */
static void test_distance_single(void)
{
    enum { W = 40, H = 30, X0 = 12, Y0 = 9 };
    uint8_t mask[W * H] = {0};
    float dist[W * H];
    mask[Y0 * W + X0] = 1;
    CHECK(fs_image_distance(mask, W, H, false, false, dist) == 0);
    double worst = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            worst = fmax(worst, fabs(dist[y * W + x] - hypot(x - X0, y - Y0)));
    CHECK_NEAR(worst, 0.0, 1e-4);
    CHECK(dist[Y0 * W + X0] == 0.0f);
}

/* With wrapping, the distance across the seam is the short way round: a pixel at x = 1 seen from
 * x = W - 2 is 3 pixels away, not W - 3; on a non-wrapping axis it stays the long way. */
static void test_distance_wrap(void)
{
    enum { W = 50, H = 20 };
    uint8_t mask[W * H] = {0};
    float dist[W * H];
    mask[5 * W + 1] = 1;
    CHECK(fs_image_distance(mask, W, H, true, false, dist) == 0);
    CHECK_NEAR(dist[5 * W + (W - 2)], 3.0, 1e-4);
    CHECK_NEAR(dist[19 * W + 1], 14.0, 1e-4);
    CHECK(fs_image_distance(mask, W, H, true, true, dist) == 0);
    CHECK_NEAR(dist[19 * W + 1], 6.0, 1e-4);
    CHECK_NEAR(dist[18 * W + (W - 1)], hypot(2.0, 7.0), 1e-4);
    CHECK(fs_image_distance(mask, W, H, false, false, dist) == 0);
    CHECK_NEAR(dist[5 * W + (W - 2)], W - 3.0, 1e-4);
}

/* Wrapped distances agree with a brute-force periodic minimum on a map whose distances exceed the
 * first padding tried (large empty regions). */
static void test_distance_wrap_far(void)
{
    enum { W = 600, H = 300 };
    uint8_t *mask = calloc(W * H, 1);
    float *dist = malloc(W * H * sizeof *dist);
    const int px[3] = {3, 590, 300}, py[3] = {2, 150, 297};
    for (int k = 0; k < 3; k++)
        mask[py[k] * W + px[k]] = 1;
    CHECK(fs_image_distance(mask, W, H, true, true, dist) == 0);
    double worst = 0.0;
    for (int y = 0; y < H; y += 7) {
        for (int x = 0; x < W; x += 5) {
            double best = INFINITY;
            for (int k = 0; k < 3; k++) {
                double dx = fabs((double)(x - px[k])), dy = fabs((double)(y - py[k]));
                dx = fmin(dx, W - dx);
                dy = fmin(dy, H - dy);
                best = fmin(best, hypot(dx, dy));
            }
            worst = fmax(worst, fabs(dist[y * W + x] - best));
        }
    }
    CHECK_NEAR(worst, 0.0, 1e-3);
    free(mask);
    free(dist);
}

/* An empty mask has no crack to be near: every distance is +inf. */
static void test_distance_empty(void)
{
    uint8_t mask[16] = {0};
    float dist[16];
    CHECK(fs_image_distance(mask, 4, 4, true, true, dist) == 0);
    CHECK(isinf(dist[0]) && isinf(dist[15]));
}

/* Area downsampling by an integer factor is the mean of each block. */
static void test_downsample(void)
{
    float src[8 * 4], dst[2 * 1];
    for (int k = 0; k < 32; k++)
        src[k] = (float)k;
    CHECK(fs_image_downsample(src, 8, 4, dst, 2, 1) == 0);
    /* Left block: columns 0..3 of rows 0..3: mean of (x + 8y) = 1.5 + 12. */
    CHECK_NEAR(dst[0], 13.5, 1e-5);
    CHECK_NEAR(dst[1], 17.5, 1e-5);
}

/* A missing file is FS_ERR_NOINPUT; a file that is not an image is FS_ERR_DATA. */
static void test_read_errors(void)
{
    fs_image img = {0};
    fs_error_clear();
    CHECK(fs_image_read(tmp_path("does-not-exist.png"), &img) == -1);
    CHECK(fs_error_domain() == FS_ERR_NOINPUT);
    CHECK(strstr(fs_error_message(), "does-not-exist.png") != NULL);
    FILE *f = fopen(tmp_path("junk.png"), "wb");
    CHECK(f != NULL);
    if (f) {
        fputs("this is not a PNG file\n", f);
        fclose(f);
    }
    fs_error_clear();
    CHECK(fs_image_read(tmp_path("junk.png"), &img) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    int w, h;
    float *g = NULL;
    fs_error_clear();
    CHECK(fs_image_read_grey(tmp_path("nothing.png"), &w, &h, &g) == -1);
    CHECK(fs_error_domain() == FS_ERR_NOINPUT);
}

/* Writing into a directory that does not exist fails with FS_ERR_IO. */
static void test_write_error(void)
{
    fs_image a;
    fs_image_alloc(&a, 4, 4, 1, FS_PIX_U8);
    fs_error_clear();
    CHECK(fs_image_write(tmp_path("no/such/dir/x.png"), &a) == -1);
    CHECK(fs_error_domain() == FS_ERR_IO);
    fs_image_free(&a);
}

/* An sRGB-tagged PNG has the chunk right after IHDR (13 bytes: length 1, "sRGB", intent 0, and
 * the CRC-32 of "sRGB\0", 0xaece1ce9, as zlib's crc32 gives it), decodes to
 * the same pixels, and an untagged one has no colour chunk. */
static void test_srgb_tag(void)
{
    fs_image a, b = {0};
    fs_image_alloc(&a, 9, 7, 3, FS_PIX_U8);
    for (size_t k = 0; k < fs_image_bytes(&a); k++)
        ((uint8_t *)a.data)[k] = (uint8_t)pattern(k);
    CHECK(fs_image_write_tagged(tmp_path("tagged.png"), &a, FS_IMAGE_SRGB) == 0);
    CHECK(fs_image_write_tagged(tmp_path("plain.png"), &a, FS_IMAGE_UNTAGGED) == 0);
    static const uint8_t chunk[13] = {0, 0, 0, 1, 's', 'R', 'G', 'B', 0, 0xae, 0xce, 0x1c, 0xe9};
    uint8_t head[46] = {0};
    FILE *f = fopen(tmp_path("tagged.png"), "rb");
    CHECK(f && fread(head, 1, sizeof head, f) == sizeof head);
    if (f)
        fclose(f);
    CHECK(memcmp(head + 12, "IHDR", 4) == 0 && memcmp(head + 33, chunk, sizeof chunk) == 0);
    f = fopen(tmp_path("plain.png"), "rb");
    CHECK(f && fread(head, 1, sizeof head, f) == sizeof head);
    if (f)
        fclose(f);
    CHECK(memcmp(head + 37, "IDAT", 4) == 0);
    CHECK(fs_image_read(tmp_path("tagged.png"), &b) == 0);
    CHECK(b.data && fs_image_bytes(&b) == fs_image_bytes(&a) && memcmp(a.data, b.data, fs_image_bytes(&a)) == 0);
    fs_image_free(&a);
    fs_image_free(&b);
}

typedef struct {
    const char *what;
    const unsigned char *bytes;
    size_t n;
    const char *format; /* NULL: unknown */
    int64_t width, height; /* 0: no size */
} probe_case;

#define BYTES(...) (const unsigned char[]){__VA_ARGS__}, sizeof((const unsigned char[]){__VA_ARGS__})

/* Headers give the format and the size without decoding, for every format fissure reads, and a
 * truncated or unknown header gives none. */
static void test_probe(void)
{
    static const char pnm[] = "P5\n# a comment\n640 480\n255\n";
    static const char pam[] = "P7\nWIDTH 12\nHEIGHT 34\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n";
    static const char pfm[] = "Pf\n7 9\n-1.0\n";
    const probe_case cases[] = {
        {"PNG", BYTES(0x89, 'P', 'N', 'G', 13, 10, 26, 10, 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0x75, 0x30, 0, 0,
                      0x4e, 0x20, 8, 0, 0, 0, 0),
         "PNG", 30000, 20000},
        {"PNG cut in IHDR", BYTES(0x89, 'P', 'N', 'G', 13, 10, 26, 10, 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0),
         "PNG", 0, 0},
        {"JPEG after APP0", BYTES(0xff, 0xd8, 0xff, 0xe0, 0, 16, 'J', 'F', 'I', 'F', 0, 1, 1, 0, 0, 1, 0, 1, 0, 0,
                                  0xff, 0xc2, 0, 17, 8, 0x01, 0xe0, 0x02, 0x80, 3),
         "JPEG", 640, 480},
        {"JPEG without a frame", BYTES(0xff, 0xd8, 0xff, 0xd9), "JPEG", 0, 0},
        {"BMP, top-down", BYTES('B', 'M', 0, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, 0x80, 2, 0, 0, 0x20, 0xfe,
                                0xff, 0xff),
         "BMP", 640, 480},
        {"BMP, OS/2 core header", BYTES('B', 'M', 0, 0, 0, 0, 0, 0, 0, 0, 26, 0, 0, 0, 12, 0, 0, 0, 100, 0, 50, 0),
         "BMP", 100, 50},
        {"TIFF, little-endian", BYTES('I', 'I', 42, 0, 8, 0, 0, 0, 2, 0, 0, 1, 3, 0, 1, 0, 0, 0, 0x2c, 1, 0, 0, 1, 1,
                                      4, 0, 1, 0, 0, 0, 200, 0, 0, 0),
         "TIFF", 300, 200},
        {"TIFF, big-endian", BYTES('M', 'M', 0, 42, 0, 0, 0, 8, 0, 2, 1, 0, 0, 4, 0, 0, 0, 1, 0, 0, 1, 0x2c, 1, 1, 0,
                                   3, 0, 0, 0, 1, 0, 200, 0, 0),
         "TIFF", 300, 200},
        {"TIFF, IFD past the end", BYTES('I', 'I', 42, 0, 0xff, 0xff, 0, 0), "TIFF", 0, 0},
        {"OpenEXR", BYTES(0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 'd', 'a', 't', 'a', 'W', 'i', 'n', 'd', 'o', 'w', 0, 'b',
                          'o', 'x', '2', 'i', 0, 16, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 99, 0, 0, 0, 49, 0, 0, 0, 0),
         "OpenEXR", 100, 50},
        {"OpenEXR, attribute size past the end", BYTES(0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 'x', 0, 'y', 0, 0xff, 0xff,
                                                       0xff, 0x7f),
         "OpenEXR", 0, 0},
        {"PGM", (const unsigned char *)pnm, sizeof pnm - 1, "PNM", 640, 480},
        {"PAM", (const unsigned char *)pam, sizeof pam - 1, "PNM", 12, 34},
        {"PFM", (const unsigned char *)pfm, sizeof pfm - 1, "PNM", 7, 9},
        {"WebP, extended", BYTES('R', 'I', 'F', 'F', 30, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', 'X', 10, 0, 0, 0,
                                 0, 0, 0, 0, 0x7f, 2, 0, 0xdf, 1, 0),
         "WebP", 640, 480},
        {"WebP, lossless", BYTES('R', 'I', 'F', 'F', 30, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', 'L', 10, 0, 0, 0,
                                 0x2f, 0x7f, 0xc2, 0x77, 0),
         "WebP", 640, 480},
        {"P7 without white space after it", BYTES('P', '7', 'W', '\n', 'W', 'I', 'D', 'T', 'H', ' ', '8', '\n'),
         NULL, 0, 0},
        {"P5 without white space after it", BYTES('P', '5', '6', '4', ' ', '4', '8', '\n'), NULL, 0, 0},
        {"GIF", BYTES('G', 'I', 'F', '8', '9', 'a', 1, 0, 1, 0), NULL, 0, 0},
        {"empty", (const unsigned char *)"", 0, NULL, 0, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const probe_case *c = &cases[i];
        fs_image_header h;
        int rc = fs_image_probe(c->bytes, c->n, &h);
        CHECK_MSG(rc == (c->width > 0 ? 0 : -1), "%s: returned %d", c->what, rc);
        CHECK_MSG(c->format ? h.format && !strcmp(h.format, c->format) : h.format == NULL, "%s: format %s", c->what,
                  h.format ? h.format : "none");
        CHECK_MSG(h.width == c->width && h.height == c->height, "%s: %lld x %lld", c->what, (long long)h.width,
                  (long long)h.height);
    }
    /* files as the writers make them */
    const char *written[] = {"g8.png", "rgb16.png", "g.exr"};
    for (int k = 0; k < 3; k++) {
        unsigned char head[4096];
        FILE *f = fopen(tmp_path(written[k]), "rb");
        size_t n = f ? fread(head, 1, sizeof head, f) : 0;
        if (f)
            fclose(f);
        fs_image_header h;
        CHECK_MSG(fs_image_probe(head, n, &h) == 0 && h.width == 37 && h.height == 23, "%s", written[k]);
    }
}

/* A map larger than the limit is refused by its header's size before any decoding (a valid
 * 30000 x 30000 grey PNG was decoded at 8 GB); the data after the header is not even looked at. */
static void test_pixel_limits(void)
{
    unsigned char png[64] = {0x89, 'P', 'N', 'G', 13, 10, 26, 10, 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                             0,    0,   0x75, 0x30, 0, 0, 0x75, 0x30, 8, 0, 0, 0, 0};
    int w = 0, h = 0;
    float *g = NULL;
    fs_error_clear();
    CHECK(fs_image_decode_grey(png, sizeof png, "huge.png", &w, &h, &g) == -1 && g == NULL);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(!strcmp(fs_error_message(), "huge.png: PNG image of 30000 x 30000 pixels: expected at most 67108864 "
                                          "pixels"),
              "%s", fs_error_message());
    /* 16385 x 16384: over what fs_image_read takes (the largest map fissure writes) */
    png[18] = 0x40;
    png[19] = 0x01;
    png[22] = 0x40;
    png[23] = 0x00;
    FILE *f = fopen(tmp_path("wide.png"), "wb");
    if (f) {
        fwrite(png, 1, sizeof png, f);
        fclose(f);
    }
    fs_image img = {0};
    fs_error_clear();
    CHECK(fs_image_read(tmp_path("wide.png"), &img) == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "16385 x 16384 pixels: expected at most 268435456 pixels") != NULL, "%s",
              fs_error_message());
    /* an unknown format is named as such */
    fs_error_clear();
    CHECK(fs_image_decode_grey((const unsigned char *)"GIF89a", 6, "a.gif", &w, &h, &g) == -1);
    CHECK_MSG(strstr(fs_error_message(), "a.gif: not an image fissure reads") != NULL, "%s", fs_error_message());
}

/* Bytes that OpenCV would hand to another decoder than the one fissure checked the header of are
 * refused before decoding. The fuzzer found a "P7" file without white space after the magic number
 * (which OpenCV's PNM readers do not claim) and with DICM at byte 128: OpenCV gave it to its DICOM
 * reader, which aborted the process. */
static void test_decoder_mismatch(void)
{
    int w = 0, h = 0;
    float *g = NULL;
    unsigned char pam[160] = "P7W!\nWIDTH 8\nHEIGHT 24\nDEPTH 1\nMAXVAL 255\nENDHDR\n";
    memcpy(pam + 128, "DICM", 4);
    fs_error_clear();
    CHECK(fs_image_decode_grey(pam, sizeof pam, "odd.pam", &w, &h, &g) == -1 && g == NULL);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "odd.pam: not an image fissure reads") != NULL, "%s", fs_error_message());
    /* a header fissure reads (WebP, lossless) with DICM at byte 128 */
    unsigned char webp[160] = {'R', 'I', 'F', 'F', 152, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', 'L', 140, 0, 0, 0,
                               0x2f, 0x7f, 0xc2, 0x77, 0};
    memcpy(webp + 128, "DICM", 4);
    fs_error_clear();
    CHECK(fs_image_decode_grey(webp, sizeof webp, "odd.webp", &w, &h, &g) == -1 && g == NULL);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(!strcmp(fs_error_message(), "odd.webp: WebP header with a DICOM marker (DICM at byte 128): refused"),
              "%s", fs_error_message());
}

/* A decoder's complaint is part of fissure's message (it printed "libpng error: ..." on stderr
 * ahead of it), and a good map decodes to its grey levels. */
static void test_decoder_message(void)
{
    fs_image a;
    fs_image_alloc(&a, 40, 30, 1, FS_PIX_U8);
    for (size_t k = 0; k < fs_image_bytes(&a); k++)
        ((uint8_t *)a.data)[k] = (uint8_t)(k % 7 * 40);
    CHECK(fs_image_write(tmp_path("grey.png"), &a) == 0);
    unsigned char buf[8192];
    FILE *f = fopen(tmp_path("grey.png"), "rb");
    size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
    if (f)
        fclose(f);
    int w = 0, h = 0;
    float *g = NULL;
    CHECK(fs_image_decode_grey(buf, n, "grey.png", &w, &h, &g) == 0 && w == 40 && h == 30);
    if (g)
        CHECK_NEAR(g[3], 120.0 / 255.0, 1e-6);
    free(g);
    g = NULL;
    buf[n - 20] ^= 0xff; /* inside the IDAT data, before the CRC */
    buf[n - 21] ^= 0xff;
    fs_error_clear();
    CHECK(fs_image_decode_grey(buf, n, "grey.png", &w, &h, &g) == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "grey.png: cannot decode the PNG image: libpng error: ") != NULL, "%s",
              fs_error_message());
    fs_image_free(&a);
}

static void remove_tmpdir(void)
{
    const char *names[] = {"g8.png", "rgb8.png", "g16.png", "rgb16.png", "g.exr", "rgb.exr", "red.png", "junk.png",
                           "tagged.png", "plain.png", "wide.png", "grey.png"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++)
        unlink(tmp_path(names[k]));
    rmdir(tmpdir);
}

int main(void)
{
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 99;
    }
    RUN(test_roundtrip);
    RUN(test_channel_order);
    RUN(test_compare_identical);
    RUN(test_compare_known);
    RUN(test_compare_mismatch);
    RUN(test_distance_single);
    RUN(test_distance_wrap);
    RUN(test_distance_wrap_far);
    RUN(test_distance_empty);
    RUN(test_downsample);
    RUN(test_read_errors);
    RUN(test_write_error);
    RUN(test_srgb_tag);
    RUN(test_probe);
    RUN(test_pixel_limits);
    RUN(test_decoder_mismatch);
    RUN(test_decoder_message);
    remove_tmpdir();
    return check_finish();
}
