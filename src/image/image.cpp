/* Image I/O, comparison, distance transform and resampling: the only file that uses OpenCV. */
#include "image/image.h"

extern "C" {
#include "base/error.h"
}

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <vector>

/* zlib level 6: the usual size/speed balance (OpenCV's default of 1 gives much larger maps). */
static const int png_compression = 6;

/* OpenCV 4.6 reads OPENCV_IO_ENABLE_OPENEXR once, on first use of the EXR codec, so it must be set
 * before any image call. A value the user set explicitly is kept (0 disables EXR on purpose). */
static void enable_exr(void)
{
    setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
}

static size_t pixel_size(fs_pixel_type t)
{
    switch (t) {
    case FS_PIX_U8:
        return 1;
    case FS_PIX_U16:
        return 2;
    case FS_PIX_F32:
        return 4;
    }
    return 1;
}

static int cv_depth(fs_pixel_type t)
{
    switch (t) {
    case FS_PIX_U8:
        return CV_8U;
    case FS_PIX_U16:
        return CV_16U;
    case FS_PIX_F32:
        return CV_32F;
    }
    return CV_8U;
}

/* Full-range value of a pixel type: what 1.0 means when images are compared on [0, 1]. */
static double full_range(fs_pixel_type t)
{
    switch (t) {
    case FS_PIX_U8:
        return 255.0;
    case FS_PIX_U16:
        return 65535.0;
    case FS_PIX_F32:
        return 1.0;
    }
    return 1.0;
}

/* A Mat header over the image's own pixels (no copy). */
static cv::Mat wrap_image(const fs_image *img)
{
    return cv::Mat(img->height, img->width, CV_MAKETYPE(cv_depth(img->type), img->channels), img->data);
}

static bool has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    if (n < e)
        return false;
    for (size_t i = 0; i < e; i++) {
        char c = path[n - e + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != ext[i])
            return false;
    }
    return true;
}

extern "C" void fs_image_alloc(fs_image *img, int width, int height, int channels, fs_pixel_type type)
{
    FS_ASSERT(width > 0 && height > 0 && channels > 0);
    img->width = width;
    img->height = height;
    img->channels = channels;
    img->type = type;
    img->data = fs_calloc((size_t)width * (size_t)height * (size_t)channels, pixel_size(type));
}

extern "C" void fs_image_free(fs_image *img)
{
    if (!img)
        return;
    free(img->data);
    img->data = NULL;
    img->width = img->height = img->channels = 0;
}

extern "C" size_t fs_image_bytes(const fs_image *img)
{
    return (size_t)img->width * (size_t)img->height * (size_t)img->channels * pixel_size(img->type);
}

/* Copies a decoded Mat into a new image, converting BGR(A) to RGB(A) and unusual depths to float. */
static int image_from_mat(const cv::Mat &m, const char *path, fs_image *out)
{
    int channels = m.channels();
    if (channels != 1 && channels != 3 && channels != 4) {
        fs_error(FS_ERR_DATA, "%s: unsupported number of channels (%d)", path, channels);
        return -1;
    }
    cv::Mat src = m;
    fs_pixel_type type;
    switch (m.depth()) {
    case CV_8U:
        type = FS_PIX_U8;
        break;
    case CV_16U:
        type = FS_PIX_U16;
        break;
    case CV_32F:
        type = FS_PIX_F32;
        break;
    default:
        type = FS_PIX_F32;
        m.convertTo(src, CV_MAKETYPE(CV_32F, channels));
        break;
    }
    fs_image_alloc(out, m.cols, m.rows, channels, type);
    cv::Mat dst = wrap_image(out);
    if (channels == 3)
        cv::cvtColor(src, dst, cv::COLOR_BGR2RGB);
    else if (channels == 4)
        cv::cvtColor(src, dst, cv::COLOR_BGRA2RGBA);
    else
        src.copyTo(dst);
    return 0;
}

/* Decodes path into a Mat; missing/unopenable files and undecodable contents are told apart. */
static int decode_file(const char *path, cv::Mat *m)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open image: %s", path, strerror(errno));
        return -1;
    }
    fclose(f);
    enable_exr();
    *m = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (m->empty()) {
        fs_error(FS_ERR_DATA, "%s: not an image in a format that can be read", path);
        return -1;
    }
    return 0;
}

extern "C" int fs_image_read(const char *path, fs_image *out)
{
    memset(out, 0, sizeof *out);
    try {
        cv::Mat m;
        if (decode_file(path, &m) != 0)
            return -1;
        return image_from_mat(m, path, out);
    } catch (const cv::Exception &e) {
        fs_image_free(out);
        fs_error(FS_ERR_DATA, "%s: cannot decode image: %s", path, e.what());
    } catch (const std::exception &e) {
        fs_image_free(out);
        fs_error(FS_ERR_INTERNAL, "%s: cannot decode image: %s", path, e.what());
    }
    return -1;
}

extern "C" int fs_image_read_grey(const char *path, int *width, int *height, float **grey)
{
    try {
        cv::Mat m;
        if (decode_file(path, &m) != 0)
            return -1;
        double scale = 1.0;
        if (m.depth() == CV_8U)
            scale = 1.0 / 255.0;
        else if (m.depth() == CV_16U)
            scale = 1.0 / 65535.0;
        int channels = m.channels();
        cv::Mat f;
        m.convertTo(f, CV_MAKETYPE(CV_32F, channels), scale);
        /* Colour is averaged over R, G, B (alpha, when present, is ignored). */
        int colour = channels >= 3 ? 3 : 1;
        size_t n = (size_t)m.cols * (size_t)m.rows;
        float *g = (float *)fs_malloc(n * sizeof(float));
        for (int y = 0; y < m.rows; y++) {
            const float *row = f.ptr<float>(y);
            for (int x = 0; x < m.cols; x++) {
                double sum = 0.0;
                for (int c = 0; c < colour; c++)
                    sum += row[(size_t)x * (size_t)channels + (size_t)c];
                g[(size_t)y * (size_t)m.cols + (size_t)x] = (float)(sum / colour);
            }
        }
        *width = m.cols;
        *height = m.rows;
        *grey = g;
        return 0;
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_DATA, "%s: cannot decode image: %s", path, e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot decode image: %s", path, e.what());
    }
    return -1;
}

/* CRC-32 of the PNG specification (ISO 3309 / ITU-T V.42, reflected polynomial 0xEDB88320) over
 * a chunk's type and data, computed bitwise: chunks we add are a few bytes long. */
static uint32_t png_crc(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* design: OpenCV's PNG encoder writes no colour chunk and has no option to add one, so the
 * encoded stream is edited: the 8-byte signature and the IHDR chunk (4 length + 4 type + 13 data +
 * 4 CRC = 25 bytes) come first, and PNG requires sRGB before PLTE and IDAT, so the chunk goes
 * right after IHDR. Rendering intent 0 (perceptual) is what sRGB-tagged textures conventionally use. */
static bool insert_srgb_chunk(std::vector<unsigned char> &png)
{
    const size_t ihdr_end = 8 + 25;
    if (png.size() < ihdr_end || memcmp(&png[12], "IHDR", 4) != 0)
        return false;
    unsigned char chunk[13];
    put_be32(chunk, 1);
    memcpy(chunk + 4, "sRGB", 4);
    chunk[8] = 0;
    put_be32(chunk + 9, png_crc(chunk + 4, 5));
    png.insert(png.begin() + (std::ptrdiff_t)ihdr_end, chunk, chunk + sizeof chunk);
    return true;
}

/* Writes bytes to exactly path. */
static int write_bytes(const char *path, const std::vector<unsigned char> &bytes)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot write image: %s", path, strerror(errno));
        return -1;
    }
    size_t wrote = fwrite(bytes.data(), 1, bytes.size(), f);
    int err = wrote == bytes.size() ? 0 : errno;
    if (fclose(f) != 0 && err == 0)
        err = errno ? errno : EIO;
    if (wrote != bytes.size() || err) {
        fs_error(FS_ERR_IO, "%s: cannot write image: %s", path, strerror(err ? err : EIO));
        return -1;
    }
    return 0;
}

extern "C" int fs_image_write(const char *path, const fs_image *img)
{
    return fs_image_write_tagged(path, img, FS_IMAGE_UNTAGGED);
}

extern "C" int fs_image_write_tagged(const char *path, const fs_image *img, fs_image_tag tag)
{
    bool exr = has_extension(path, ".exr");
    bool png = has_extension(path, ".png");
    if (exr && img->type != FS_PIX_F32) {
        fs_error(FS_ERR_INTERNAL, "%s: EXR output needs float pixels", path);
        return -1;
    }
    if (png && img->type == FS_PIX_F32) {
        fs_error(FS_ERR_INTERNAL, "%s: PNG output needs 8- or 16-bit pixels", path);
        return -1;
    }
    if (img->channels != 1 && img->channels != 3 && img->channels != 4) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot write %d channels", path, img->channels);
        return -1;
    }
    try {
        enable_exr();
        cv::Mat src = wrap_image(img), m;
        if (img->channels == 3)
            cv::cvtColor(src, m, cv::COLOR_RGB2BGR);
        else if (img->channels == 4)
            cv::cvtColor(src, m, cv::COLOR_RGBA2BGRA);
        else
            m = src;
        std::vector<int> params;
        if (png) {
            params.push_back(cv::IMWRITE_PNG_COMPRESSION);
            params.push_back(png_compression);
        } else if (exr) {
            params.push_back(cv::IMWRITE_EXR_TYPE);
            params.push_back(cv::IMWRITE_EXR_TYPE_FLOAT);
        }
        if (png && tag == FS_IMAGE_SRGB) {
            std::vector<unsigned char> bytes;
            if (!cv::imencode(".png", m, bytes, params) || !insert_srgb_chunk(bytes)) {
                fs_error(FS_ERR_INTERNAL, "%s: cannot encode PNG", path);
                return -1;
            }
            return write_bytes(path, bytes);
        }
        if (!cv::imwrite(path, m, params)) {
            fs_error(FS_ERR_IO, "%s: cannot write image", path);
            return -1;
        }
        return 0;
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_IO, "%s: cannot write image: %s", path, e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot write image: %s", path, e.what());
    }
    return -1;
}

/* Mean SSIM of two single-channel images on [0, 1] (Wang et al. 2004: Gaussian 11x11, sigma 1.5,
 * C1 = (0.01 L)^2, C2 = (0.03 L)^2 with L = 1; borders reflected). */
static double ssim_channel(const cv::Mat &a, const cv::Mat &b)
{
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    const cv::Size win(11, 11);
    const double sigma = 1.5;
    cv::Mat mu_a, mu_b, aa, bb, ab;
    cv::GaussianBlur(a, mu_a, win, sigma, sigma, cv::BORDER_REFLECT);
    cv::GaussianBlur(b, mu_b, win, sigma, sigma, cv::BORDER_REFLECT);
    cv::GaussianBlur(a.mul(a), aa, win, sigma, sigma, cv::BORDER_REFLECT);
    cv::GaussianBlur(b.mul(b), bb, win, sigma, sigma, cv::BORDER_REFLECT);
    cv::GaussianBlur(a.mul(b), ab, win, sigma, sigma, cv::BORDER_REFLECT);
    cv::Mat mu_aa = mu_a.mul(mu_a), mu_bb = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
    cv::Mat var_a = aa - mu_aa, var_b = bb - mu_bb, cov = ab - mu_ab;
    cv::Mat num = (2.0 * mu_ab + c1).mul(2.0 * cov + c2);
    cv::Mat den = (mu_aa + mu_bb + c1).mul(var_a + var_b + c2);
    cv::Mat ssim;
    cv::divide(num, den, ssim);
    return cv::mean(ssim)[0];
}

extern "C" int fs_image_compare(const fs_image *a, const fs_image *b, fs_image_diff *out)
{
    if (a->width != b->width || a->height != b->height || a->channels != b->channels) {
        fs_error(FS_ERR_DATA, "images differ in size or channels (%dx%d x%d vs %dx%d x%d)", a->width,
                 a->height, a->channels, b->width, b->height, b->channels);
        return -1;
    }
    try {
        int ch = a->channels;
        cv::Mat fa, fb;
        wrap_image(a).convertTo(fa, CV_MAKETYPE(CV_64F, ch), 1.0 / full_range(a->type));
        wrap_image(b).convertTo(fb, CV_MAKETYPE(CV_64F, ch), 1.0 / full_range(b->type));
        cv::Mat diff;
        cv::absdiff(fa, fb, diff);
        double max_diff = 0.0;
        cv::minMaxLoc(diff.reshape(1), NULL, &max_diff);
        cv::Mat sq = diff.mul(diff);
        cv::Scalar per_channel = cv::mean(sq);
        double mse = 0.0;
        for (int c = 0; c < ch; c++)
            mse += per_channel[c];
        mse /= ch;
        out->psnr = mse > 0.0 ? 10.0 * log10(1.0 / mse) : HUGE_VAL;
        out->max_diff = max_diff;
        std::vector<cv::Mat> ca, cb;
        cv::split(fa, ca);
        cv::split(fb, cb);
        double ssim = 0.0;
        for (int c = 0; c < ch; c++)
            ssim += ssim_channel(ca[(size_t)c], cb[(size_t)c]);
        out->ssim = ssim / ch;
        return 0;
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_INTERNAL, "image comparison failed: %s", e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "image comparison failed: %s", e.what());
    }
    return -1;
}

/* design: OpenCV's exact Euclidean transform (DIST_MASK_PRECISE) knows nothing of periodicity, so
 * wrapping axes are padded with copies of the opposite side (BORDER_WRAP) and the centre is cropped.
 * A pad of p pixels is enough for every pixel whose distance comes out <= p (its true nearest crack
 * copy is then inside the padded image). The pad starts small and doubles until that holds; half the
 * period always suffices, since every crack has a copy within half a period along each axis. This
 * keeps a 4096 x 4096 map with crack spacing under ~256 px near 1x memory instead of 9x. */
extern "C" int fs_image_distance(const uint8_t *mask, int width, int height, bool wrap_u, bool wrap_v, float *dist)
{
    size_t n = (size_t)width * (size_t)height;
    bool any = false;
    for (size_t i = 0; i < n && !any; i++)
        any = mask[i] != 0;
    if (!any) {
        for (size_t i = 0; i < n; i++)
            dist[i] = HUGE_VALF;
        return 0;
    }
    try {
        /* distanceTransform measures the distance to the nearest zero pixel. */
        cv::Mat src(height, width, CV_8U);
        for (int y = 0; y < height; y++) {
            uint8_t *row = src.ptr<uint8_t>(y);
            for (int x = 0; x < width; x++)
                row[x] = mask[(size_t)y * (size_t)width + (size_t)x] ? 0 : 255;
        }
        cv::Mat out(height, width, CV_32F, dist);
        if (!wrap_u && !wrap_v) {
            cv::distanceTransform(src, out, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
            return 0;
        }
        const int full_u = wrap_u ? width / 2 + 1 : 0, full_v = wrap_v ? height / 2 + 1 : 0;
        for (int pad = 128;; pad *= 2) {
            int pu = std::min(pad, full_u), pv = std::min(pad, full_v);
            cv::Mat padded, d;
            cv::copyMakeBorder(src, padded, pv, pv, pu, pu, cv::BORDER_WRAP);
            cv::distanceTransform(padded, d, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
            d(cv::Rect(pu, pv, width, height)).copyTo(out);
            bool complete = pu == full_u && pv == full_v;
            double max_d = 0.0;
            cv::minMaxLoc(out, NULL, &max_d);
            if (complete || max_d <= (double)pad)
                return 0;
        }
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_INTERNAL, "distance transform failed: %s", e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "distance transform failed: %s", e.what());
    }
    return -1;
}

extern "C" int fs_image_downsample(const float *src, int src_w, int src_h, float *dst, int dst_w, int dst_h)
{
    try {
        cv::Mat s(src_h, src_w, CV_32F, const_cast<float *>(src));
        cv::Mat d(dst_h, dst_w, CV_32F, dst);
        cv::resize(s, d, cv::Size(dst_w, dst_h), 0.0, 0.0, cv::INTER_AREA);
        return 0;
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_INTERNAL, "resampling failed: %s", e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "resampling failed: %s", e.what());
    }
    return -1;
}
