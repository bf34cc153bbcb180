/* Image headers: the format and the size of an image file from its bytes, before any decoder runs. */
#include "image/image.h"

#include <stdbool.h>
#include <string.h>

static uint32_t be16(const unsigned char *p) { return (uint32_t)p[0] << 8 | p[1]; }
static uint32_t le16(const unsigned char *p) { return (uint32_t)p[1] << 8 | p[0]; }
static uint32_t be32(const unsigned char *p) { return be16(p) << 16 | be16(p + 2); }
static uint32_t le32(const unsigned char *p) { return le16(p + 2) << 16 | le16(p); }

static int found(fs_image_header *out, const char *format, int64_t width, int64_t height)
{
    out->format = format;
    out->width = width;
    out->height = height;
    return width > 0 && height > 0 ? 0 : -1;
}

/* PNG: the signature, then IHDR with width and height (ISO/IEC 15948). */
static int probe_png(const unsigned char *d, size_t n, fs_image_header *out)
{
    if (n < 24 || memcmp(d + 12, "IHDR", 4) != 0)
        return found(out, "PNG", 0, 0);
    return found(out, "PNG", be32(d + 16), be32(d + 20));
}

/* JPEG: markers from SOI on, each FF xx followed by a big-endian length that counts itself, up to
 * the first start-of-frame (SOF0-SOF15 but DHT C4, JPG C8 and DAC CC), which holds the precision,
 * the height and the width. */
static int probe_jpeg(const unsigned char *d, size_t n, fs_image_header *out)
{
    size_t p = 2;
    while (p + 1 < n) {
        if (d[p] != 0xff)
            break;
        unsigned m = d[p + 1];
        if (m == 0xff) { /* fill byte */
            p++;
            continue;
        }
        p += 2;
        if (m == 0x01 || (m >= 0xd0 && m <= 0xd8)) /* markers without a segment */
            continue;
        if (m == 0xd9 || m == 0xda || p + 2 > n) /* end of image, or scan data before any frame */
            break;
        size_t len = be16(d + p);
        if (len < 2)
            break;
        if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
            if (len < 7 || p + 7 > n)
                break;
            return found(out, "JPEG", be16(d + p + 5), be16(d + p + 3));
        }
        p += len;
    }
    return found(out, "JPEG", 0, 0);
}

/* BMP: the file header (14 bytes), then the DIB header: OS/2's 12-byte core header with 16-bit sizes,
 * or the 40-byte and later ones with 32-bit signed sizes (a negative height runs top-down). */
static int probe_bmp(const unsigned char *d, size_t n, fs_image_header *out)
{
    if (n < 18)
        return found(out, "BMP", 0, 0);
    uint32_t dib = le32(d + 14);
    if (dib == 12)
        return n < 22 ? found(out, "BMP", 0, 0) : found(out, "BMP", le16(d + 18), le16(d + 20));
    if (n < 26)
        return found(out, "BMP", 0, 0);
    int64_t w = (int32_t)le32(d + 18), h = (int32_t)le32(d + 22);
    return found(out, "BMP", w, h < 0 ? -h : h);
}

/* TIFF (classic, not BigTIFF): the byte order, the offset of the first IFD, and in it the
 * ImageWidth (256) and ImageLength (257) entries, SHORT or LONG. */
static int probe_tiff(const unsigned char *d, size_t n, fs_image_header *out)
{
    bool little = d[0] == 'I';
    uint32_t (*u16)(const unsigned char *) = little ? le16 : be16;
    uint32_t (*u32)(const unsigned char *) = little ? le32 : be32;
    if (n < 8 || u16(d + 2) != 42)
        return found(out, "TIFF", 0, 0);
    size_t ifd = u32(d + 4);
    if (ifd > n || n - ifd < 2)
        return found(out, "TIFF", 0, 0);
    size_t count = u16(d + ifd);
    int64_t w = 0, h = 0;
    for (size_t i = 0; i < count; i++) {
        size_t e = ifd + 2 + 12 * i;
        if (e > n || n - e < 12)
            break;
        uint32_t tag = u16(d + e), type = u16(d + e + 2);
        if (tag != 256 && tag != 257)
            continue;
        int64_t v = type == 3 ? (int64_t)u16(d + e + 8) : type == 4 ? (int64_t)u32(d + e + 8) : 0;
        if (tag == 256)
            w = v;
        else
            h = v;
    }
    return found(out, "TIFF", w, h);
}

/* OpenEXR: magic and version, then the header's attributes (name NUL, type NUL, 32-bit size,
 * value) up to an empty name; dataWindow is a box2i, xMin yMin xMax yMax. */
static int probe_exr(const unsigned char *d, size_t n, fs_image_header *out)
{
    size_t p = 8;
    while (p < n && d[p] != 0) {
        const unsigned char *name = d + p, *end = memchr(name, 0, n - p);
        if (!end)
            break;
        size_t q = (size_t)(end - d) + 1;
        const unsigned char *type_end = q < n ? memchr(d + q, 0, n - q) : NULL;
        if (!type_end)
            break;
        size_t v = (size_t)(type_end - d) + 1;
        if (v > n || n - v < 4)
            break;
        uint32_t size = le32(d + v);
        v += 4;
        if (size > n - v)
            break;
        if (!strcmp((const char *)name, "dataWindow") && !strcmp((const char *)d + q, "box2i") && size == 16) {
            int64_t x0 = (int32_t)le32(d + v), y0 = (int32_t)le32(d + v + 4);
            int64_t x1 = (int32_t)le32(d + v + 8), y1 = (int32_t)le32(d + v + 12);
            return found(out, "OpenEXR", x1 - x0 + 1, y1 - y0 + 1);
        }
        p = v + size;
    }
    return found(out, "OpenEXR", 0, 0);
}

/* PNM white space: that of C's isspace in the C locale. */
static bool pnm_space(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* A decimal field of a PNM header after white space and # comments; -1 when there is none. */
static int64_t pnm_number(const unsigned char *d, size_t n, size_t *p)
{
    for (;;) {
        while (*p < n && pnm_space(d[*p]))
            (*p)++;
        if (*p < n && d[*p] == '#') {
            while (*p < n && d[*p] != '\n')
                (*p)++;
            continue;
        }
        break;
    }
    int64_t v = 0;
    size_t start = *p;
    while (*p < n && d[*p] >= '0' && d[*p] <= '9' && v < ((int64_t)1 << 40))
        v = 10 * v + (d[(*p)++] - '0');
    return *p > start ? v : -1;
}

/* PNM: P1-P6 (and PF/Pf, the float maps) give the width and the height as the first two numbers;
 * PAM (P7) has WIDTH and HEIGHT lines before ENDHDR. */
static int probe_pnm(const unsigned char *d, size_t n, fs_image_header *out)
{
    size_t p = 2;
    if (d[1] != '7') {
        int64_t w = pnm_number(d, n, &p);
        int64_t h = pnm_number(d, n, &p);
        return found(out, "PNM", w, h);
    }
    int64_t w = 0, h = 0;
    while (p < n) {
        size_t line = p;
        while (p < n && d[p] != '\n')
            p++;
        size_t len = p - line;
        p++;
        if (len >= 6 && !memcmp(d + line, "ENDHDR", 6))
            break;
        size_t q = line + 6;
        if (len > 6 && !memcmp(d + line, "WIDTH ", 6))
            w = pnm_number(d, line + len, &q);
        q = line + 7;
        if (len > 7 && !memcmp(d + line, "HEIGHT ", 7))
            h = pnm_number(d, line + len, &q);
    }
    return found(out, "PNM", w, h);
}

/* WebP: RIFF....WEBP, then a VP8 (lossy: 14-bit sizes after the start code 9d 01 2a), VP8L
 * (lossless: signature 2f, then 14 bits of width - 1 and of height - 1) or VP8X (extended: 24 bits
 * of canvas width - 1 and height - 1) chunk. */
static int probe_webp(const unsigned char *d, size_t n, fs_image_header *out)
{
    if (n >= 30 && !memcmp(d + 12, "VP8 ", 4) && d[23] == 0x9d && d[24] == 0x01 && d[25] == 0x2a)
        return found(out, "WebP", le16(d + 26) & 0x3fff, le16(d + 28) & 0x3fff);
    if (n >= 25 && !memcmp(d + 12, "VP8L", 4) && d[20] == 0x2f) {
        uint32_t bits = le32(d + 21);
        return found(out, "WebP", (bits & 0x3fff) + 1, ((bits >> 14) & 0x3fff) + 1);
    }
    if (n >= 30 && !memcmp(d + 12, "VP8X", 4)) {
        int64_t w = (int64_t)(d[24] | d[25] << 8 | d[26] << 16) + 1, h = (int64_t)(d[27] | d[28] << 8 | d[29] << 16) + 1;
        return found(out, "WebP", w, h);
    }
    return found(out, "WebP", 0, 0);
}

int fs_image_probe(const unsigned char *data, size_t n, fs_image_header *out)
{
    memset(out, 0, sizeof *out);
    if (n >= 8 && !memcmp(data, "\x89PNG\r\n\x1a\n", 8))
        return probe_png(data, n, out);
    if (n >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
        return probe_jpeg(data, n, out);
    if (n >= 2 && data[0] == 'B' && data[1] == 'M')
        return probe_bmp(data, n, out);
    if (n >= 4 && (!memcmp(data, "II*\0", 4) || !memcmp(data, "MM\0*", 4)))
        return probe_tiff(data, n, out);
    if (n >= 8 && !memcmp(data, "\x76\x2f\x31\x01", 4))
        return probe_exr(data, n, out);
    /* the white space after the magic number is part of the PNM signature for OpenCV's decoders too:
     * without it they leave the bytes to the next decoder that claims them */
    if (n >= 3 && data[0] == 'P' && ((data[1] >= '1' && data[1] <= '7') || data[1] == 'F' || data[1] == 'f') &&
        pnm_space(data[2]))
        return probe_pnm(data, n, out);
    if (n >= 16 && !memcmp(data, "RIFF", 4) && !memcmp(data + 8, "WEBP", 4))
        return probe_webp(data, n, out);
    return -1;
}
