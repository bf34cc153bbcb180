/* Images: reading, atomic writing, comparison and distance transforms (C interface to OpenCV,
 * implemented in image.cpp, the only file that includes OpenCV). */
#ifndef FS_IMAGE_IMAGE_H
#define FS_IMAGE_IMAGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { FS_PIX_U8 = 0, FS_PIX_U16 = 1, FS_PIX_F32 = 2 } fs_pixel_type;

/* Interleaved pixels, rows top to bottom; RGB order for three channels. */
typedef struct {
    int width, height, channels;
    fs_pixel_type type;
    void *data;   /* width * height * channels elements, owned */
} fs_image;

/* Allocates a zeroed image. */
void fs_image_alloc(fs_image *img, int width, int height, int channels, fs_pixel_type type);
void fs_image_free(fs_image *img);
size_t fs_image_bytes(const fs_image *img);

/* Most pixels of an image fs_image_read decodes: the largest map fissure writes (16384 x 16384). */
#define FS_IMAGE_MAX_PIXELS ((int64_t)16384 * 16384)
/* Most pixels of a grey-level input map (fs_image_read_grey), 8192 x 8192 or any other shape of as
 * many: a map is averaged over elements, and decoding one costs up to 12 bytes a pixel. */
#define FS_IMAGE_MAX_MAP_PIXELS ((int64_t)8192 * 8192)
/* Largest image file read. */
#define FS_IMAGE_MAX_FILE_BYTES ((int64_t)1 << 30)

/* The format and size an image file declares in its header. */
typedef struct {
    const char *format;    /* "PNG", "JPEG", "TIFF", "OpenEXR", "WebP", "BMP", "PNM"; NULL if unknown */
    int64_t width, height; /* as declared, 0 when the header gives none that can be read */
} fs_image_header;

/* Reads the format and size from the first bytes of an image (data, n bytes), without decoding.
 * Returns 0, or -1 for an unknown format (format NULL) or a header without a readable size (format
 * set, sizes 0). Implemented in probe.c (no library). */
int fs_image_probe(const unsigned char *data, size_t n, fs_image_header *out);

/* Reads a PNG, JPEG, TIFF, OpenEXR, WebP, BMP or PNM file (a regular file of at most
 * FS_IMAGE_MAX_FILE_BYTES, whose header declares at most FS_IMAGE_MAX_PIXELS), keeping bit depth
 * and channels (BGR converted to RGB). The size is checked from the header before decoding.
 * Returns 0, or -1 with fs_error(FS_ERR_NOINPUT) for a missing or irregular file, FS_ERR_DATA for
 * an unreadable, unknown or too large one (the decoder's own message included). */
int fs_image_read(const char *path, fs_image *out);

/* Reads an image as grey levels in [0, 1] (any depth, colour averaged), as fs_image_read does but
 * with at most FS_IMAGE_MAX_MAP_PIXELS. */
int fs_image_read_grey(const char *path, int *width, int *height, float **grey);

/* fs_image_read_grey of an image in memory (data, n bytes); `origin` names it in messages. */
int fs_image_decode_grey(const unsigned char *data, size_t n, const char *origin, int *width, int *height,
                         float **grey);

/* Writes the image to exactly `path` (format from its extension: .png, .exr). Not atomic by itself:
 * io/output.h stages files under temporary names. Returns 0 or -1 with fs_error(FS_ERR_IO). */
int fs_image_write(const char *path, const fs_image *img);

/* How a PNG declares the colour space of its pixels. */
typedef enum {
    FS_IMAGE_UNTAGGED = 0, /* no colour chunk: data (heights, normals, masks, ids) read as raw values */
    FS_IMAGE_SRGB = 1      /* an sRGB chunk (perceptual intent) right after IHDR: colour maps */
} fs_image_tag;

/* fs_image_write with a colour-space tag. For PNG, FS_IMAGE_SRGB inserts an sRGB chunk after
 * IHDR (fs_image_write writes untagged PNGs, which is FS_IMAGE_UNTAGGED); other formats ignore the
 * tag. Returns 0 or -1 with fs_error(FS_ERR_IO). */
int fs_image_write_tagged(const char *path, const fs_image *img, fs_image_tag tag);

typedef struct {
    double psnr;      /* dB over all channels, +inf when identical */
    double ssim;      /* mean SSIM over channels (Gaussian 11x11, sigma 1.5) */
    double max_diff;  /* largest absolute difference, as a fraction of the full range */
} fs_image_diff;

/* Compares two images of the same size and channel count (depths may differ: both are scaled to
 * [0,1]). Returns 0, or -1 with fs_error(FS_ERR_DATA) when sizes or channels differ. */
int fs_image_compare(const fs_image *a, const fs_image *b, fs_image_diff *out);

/* Euclidean distance (pixels) from each pixel to the nearest pixel with mask != 0; wraps on the
 * given axes so that distances continue across the seam. dist has width * height floats (+inf
 * everywhere when the mask is empty). Returns 0, or -1 with fs_error(FS_ERR_INTERNAL). */
int fs_image_distance(const uint8_t *mask, int width, int height, bool wrap_u, bool wrap_v, float *dist);

/* Area-averaging resize of a float single-channel buffer (used for supersampling).
 * Returns 0, or -1 with fs_error(FS_ERR_INTERNAL). */
int fs_image_downsample(const float *src, int src_w, int src_h, float *dst, int dst_w, int dst_h);

#ifdef __cplusplus
}
#endif

#endif
