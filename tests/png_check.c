/* Test helper: PNG chunk structure (colour chunks, CRCs) and channel relations between written maps. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "image/image.h"

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* CRC-32 of the PNG specification, computed independently of the writer's (table-driven). */
static uint32_t crc32_png(const unsigned char *p, size_t n)
{
    static uint32_t table[256];
    if (!table[1])
        for (uint32_t i = 0; i < 256; i++) {
            uint32_t c = i;
            for (int k = 0; k < 8; k++)
                c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
            table[i] = c;
        }
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++)
        c = table[(c ^ p[i]) & 0xff] ^ (c >> 8);
    return c ^ 0xffffffffu;
}

/* Prints "WIDTH HEIGHT DEPTH COLORTYPE TAGS" where TAGS lists the colour chunks found (sRGB, gAMA,
 * cHRM, iCCP) or "untagged". Fails when a CRC is wrong, the first chunk is not IHDR, a colour chunk
 * comes after IDAT, or an sRGB chunk is not one byte of a valid rendering intent. */
static int info(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "png_check: cannot open %s\n", path);
        return 2;
    }
    size_t cap = 1 << 20, n = 0, got;
    unsigned char *buf = malloc(cap);
    while ((got = fread(buf + n, 1, cap - n, f)) > 0)
        if ((n += got) == cap)
            buf = realloc(buf, cap *= 2);
    fclose(f);
    static const unsigned char sig[8] = {137, 'P', 'N', 'G', 13, 10, 26, 10};
    int bad = n < 33 || memcmp(buf, sig, 8) != 0 || memcmp(buf + 12, "IHDR", 4) != 0;
    char tags[64] = "";
    int seen_idat = 0;
    for (size_t p = 8; !bad && p + 12 <= n;) {
        uint32_t len = be32(buf + p);
        if (p + 12 + len > n) {
            bad = 1;
            break;
        }
        const unsigned char *type = buf + p + 4;
        if (crc32_png(type, 4 + (size_t)len) != be32(buf + p + 8 + len)) {
            fprintf(stderr, "png_check: %s: bad CRC in %.4s\n", path, (const char *)type);
            bad = 1;
        }
        const char *colour[] = {"sRGB", "gAMA", "cHRM", "iCCP"};
        for (int c = 0; c < 4; c++)
            if (!memcmp(type, colour[c], 4)) {
                if (seen_idat)
                    bad = 1;
                if (c == 0 && (len != 1 || type[4] > 3))
                    bad = 1;
                strcat(tags, tags[0] ? "," : "");
                strcat(tags, colour[c]);
            }
        seen_idat |= !memcmp(type, "IDAT", 4);
        if (!memcmp(type, "IEND", 4))
            break;
        p += 12 + len;
    }
    if (bad) {
        fprintf(stderr, "png_check: %s: malformed PNG\n", path);
        free(buf);
        return 1;
    }
    printf("%u %u %u %u %s\n", be32(buf + 16), be32(buf + 20), buf[24], buf[25], tags[0] ? tags : "untagged");
    free(buf);
    return 0;
}

static int load(const char *path, fs_image *img)
{
    if (fs_image_read(path, img) < 0) {
        fprintf(stderr, "png_check: %s\n", fs_error_message());
        return -1;
    }
    if (img->type != FS_PIX_U8) {
        fprintf(stderr, "png_check: %s: expected 8-bit samples\n", path);
        return -1;
    }
    return 0;
}

/* Exit 0 when B has A's red and blue and the inverse of its green (255 - g) at every pixel. */
static int greenflip(const char *a_path, const char *b_path)
{
    fs_image a = {0}, b = {0};
    if (load(a_path, &a) < 0 || load(b_path, &b) < 0)
        return 2;
    int bad = a.width != b.width || a.height != b.height || a.channels != 3 || b.channels != 3;
    size_t n = (size_t)a.width * (size_t)a.height, wrong = 0;
    const uint8_t *pa = a.data, *pb = b.data;
    for (size_t k = 0; !bad && k < n; k++)
        wrong += pa[3 * k] != pb[3 * k] || pb[3 * k + 1] != 255 - pa[3 * k + 1] || pa[3 * k + 2] != pb[3 * k + 2];
    printf("%zu of %zu pixels differ from a green flip\n", wrong, n);
    fs_image_free(&a);
    fs_image_free(&b);
    return bad || wrong ? 1 : 0;
}

/* Exit 0 when channel ca of A equals channel cb of B everywhere, or (B = "=V") the constant V. */
static int channel(const char *a_path, int ca, const char *b_path, int cb)
{
    fs_image a = {0}, b = {0};
    if (load(a_path, &a) < 0)
        return 2;
    int constant = b_path[0] == '=' ? atoi(b_path + 1) : -1;
    if (constant < 0 && load(b_path, &b) < 0)
        return 2;
    int bad = ca >= a.channels || (constant < 0 && (cb >= b.channels || a.width != b.width || a.height != b.height));
    size_t n = (size_t)a.width * (size_t)a.height, wrong = 0;
    const uint8_t *pa = a.data, *pb = b.data;
    for (size_t k = 0; !bad && k < n; k++) {
        int want = constant >= 0 ? constant : pb[k * (size_t)b.channels + (size_t)cb];
        wrong += pa[k * (size_t)a.channels + (size_t)ca] != want;
    }
    printf("%zu of %zu pixels differ\n", wrong, n);
    fs_image_free(&a);
    fs_image_free(&b);
    return bad || wrong ? 1 : 0;
}

/* Prints the number of distinct non-zero values of a single-channel 16-bit image (fragment ids). */
static int ids(const char *path)
{
    fs_image img = {0};
    if (fs_image_read(path, &img) < 0 || img.type != FS_PIX_U16 || img.channels != 1) {
        fprintf(stderr, "png_check: %s: expected a 16-bit grey image\n", path);
        return 2;
    }
    static unsigned char seen[65536];
    const uint16_t *p = img.data;
    int count = 0;
    for (size_t k = 0; k < (size_t)img.width * (size_t)img.height; k++) {
        count += p[k] && !seen[p[k]];
        seen[p[k]] = 1;
    }
    printf("%d\n", count);
    fs_image_free(&img);
    return 0;
}

/* Prints the mean of a single-channel 8-bit image as a fraction of 255 (a crack mask's coverage). */
static int coverage(const char *path)
{
    fs_image img = {0};
    if (fs_image_read(path, &img) < 0 || img.type != FS_PIX_U8 || img.channels != 1) {
        fprintf(stderr, "png_check: %s: expected an 8-bit grey image\n", path);
        return 2;
    }
    const uint8_t *p = img.data;
    size_t n = (size_t)img.width * (size_t)img.height;
    uint64_t sum = 0;
    for (size_t k = 0; k < n; k++)
        sum += p[k];
    printf("%.6f\n", (double)sum / (255.0 * (double)n));
    fs_image_free(&img);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "info"))
        return info(argv[2]);
    if (argc == 4 && !strcmp(argv[1], "greenflip"))
        return greenflip(argv[2], argv[3]);
    if (argc == 6 && !strcmp(argv[1], "channel"))
        return channel(argv[2], atoi(argv[3]), argv[4], atoi(argv[5]));
    if (argc == 3 && !strcmp(argv[1], "ids"))
        return ids(argv[2]);
    if (argc == 3 && !strcmp(argv[1], "coverage"))
        return coverage(argv[2]);
    fprintf(stderr, "usage: png_check info PNG | greenflip OPENGL DIRECTX | channel A CA B|=V CB | ids PNG | "
            "coverage PNG\n");
    return 2;
}
