/* Image I/O, comparison, distance transform and resampling: the only file that uses OpenCV. */
#include "image/image.h"

extern "C" {
#include "base/error.h"
}

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <limits>
#include <string>
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

/* design: libpng, libjpeg, OpenEXR and OpenCV report their errors by printing them on stderr
 * ("libpng error: IDAT: CRC error", OpenCV's "[ WARN...]" lines) before returning failure, which put
 * raw lines ahead of fissure's own message. While a codec runs, file descriptor 2 points to an
 * anonymous temporary file; what the codec printed becomes part of fissure's message when it
 * fails, and is dropped when it succeeds. The codecs run on the calling thread while no other
 * thread of fissure prints. */
class stderr_capture {
  public:
    stderr_capture()
    {
        fflush(stderr);
        tmp_ = tmpfile();
        if (!tmp_)
            return;
        saved_ = dup(2);
        if (saved_ < 0 || dup2(fileno(tmp_), 2) < 0) {
            if (saved_ >= 0)
                close(saved_);
            saved_ = -1;
            fclose(tmp_);
            tmp_ = NULL;
        }
    }
    ~stderr_capture() { restore(); }
    /* Puts stderr back and returns the last line the codec printed ("" if none). */
    std::string restore()
    {
        std::string last;
        if (!tmp_)
            return last;
        fflush(stderr);
        std::cerr.flush();
        dup2(saved_, 2);
        close(saved_);
        char buf[4096];
        rewind(tmp_);
        size_t n = fread(buf, 1, sizeof buf - 1, tmp_);
        buf[n] = '\0';
        fclose(tmp_);
        tmp_ = NULL;
        std::string text(buf);
        while (!text.empty() && (text.back() == '\n' || text.back() == ' '))
            text.pop_back();
        size_t nl = text.rfind('\n');
        last = nl == std::string::npos ? text : text.substr(nl + 1);
        return last;
    }

  private:
    FILE *tmp_ = NULL;
    int saved_ = -1;
};

/* Reads a whole regular file of at most FS_IMAGE_MAX_FILE_BYTES into bytes; missing or irregular
 * files (FS_ERR_NOINPUT) and read failures (FS_ERR_IO) are told apart. The open does not block on a
 * FIFO, and the checks are on the opened file. */
static int read_bytes(const char *path, std::vector<unsigned char> *bytes)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open image: %s", path, strerror(errno));
        return -1;
    }
    struct stat st;
    int status = fstat(fd, &st) != 0 ? errno : S_ISDIR(st.st_mode) ? EISDIR : 0;
    if (status != 0 || !S_ISREG(st.st_mode)) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open image: %s", path, status ? strerror(status) : "not a regular file");
        close(fd);
        return -1;
    }
    if (st.st_size > FS_IMAGE_MAX_FILE_BYTES) {
        fs_error(FS_ERR_DATA, "%s: image file of %lld bytes: expected at most %lld", path, (long long)st.st_size,
                 (long long)FS_IMAGE_MAX_FILE_BYTES);
        close(fd);
        return -1;
    }
    bytes->resize((size_t)st.st_size);
    size_t got = 0;
    while (got < bytes->size()) {
        ssize_t r = read(fd, bytes->data() + got, bytes->size() - got);
        if (r < 0 && (errno == EINTR || errno == EAGAIN))
            continue;
        if (r <= 0) {
            int err = r < 0 ? errno : 0;
            fs_error(FS_ERR_IO, "%s: cannot read image: %s", path, err ? strerror(err) : "the file got shorter");
            close(fd);
            return -1;
        }
        got += (size_t)r;
    }
    close(fd);
    return 0;
}

/* Decodes an image in memory into a Mat after checking its header: a format fissure reads and at
 * most max_pixels, refused before any decoding. */
static int decode_bytes(const std::vector<unsigned char> &bytes, const char *origin, int64_t max_pixels, cv::Mat *m)
{
    fs_image_header h;
    if (fs_image_probe(bytes.data(), bytes.size(), &h) != 0) {
        if (!h.format)
            fs_error(FS_ERR_DATA, "%s: not an image fissure reads: expected PNG, JPEG, TIFF, OpenEXR, WebP, BMP or PNM",
                     origin);
        else
            fs_error(FS_ERR_DATA, "%s: %s image without a valid size in its header", origin, h.format);
        return -1;
    }
    /* OpenCV hands bytes whose own decoder does not claim them to the next one that does, and its
     * DICOM reader (GDCM) claims anything with DICM at byte 128 and aborts the process on a bad file */
    if (bytes.size() >= 132 && !memcmp(bytes.data() + 128, "DICM", 4)) {
        fs_error(FS_ERR_DATA, "%s: %s header with a DICOM marker (DICM at byte 128): refused", origin, h.format);
        return -1;
    }
    if (h.width > FS_IMAGE_MAX_PIXELS || h.height > FS_IMAGE_MAX_PIXELS || h.width * h.height > max_pixels) {
        fs_error(FS_ERR_DATA, "%s: %s image of %lld x %lld pixels: expected at most %lld pixels", origin, h.format,
                 (long long)h.width, (long long)h.height, (long long)max_pixels);
        return -1;
    }
    enable_exr();
    stderr_capture capture;
    *m = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
    std::string said = capture.restore();
    if (m->empty()) {
        fs_error(FS_ERR_DATA, "%s: cannot decode the %s image%s%s", origin, h.format, said.empty() ? "" : ": ",
                 said.c_str());
        return -1;
    }
    if ((int64_t)m->cols != h.width || (int64_t)m->rows != h.height) {
        fs_error(FS_ERR_DATA, "%s: the %s image decodes to %d x %d pixels, its header says %lld x %lld", origin,
                 h.format, m->cols, m->rows, (long long)h.width, (long long)h.height);
        return -1;
    }
    return 0;
}

extern "C" int fs_image_read(const char *path, fs_image *out)
{
    memset(out, 0, sizeof *out);
    try {
        std::vector<unsigned char> bytes;
        cv::Mat m;
        if (read_bytes(path, &bytes) != 0 || decode_bytes(bytes, path, FS_IMAGE_MAX_PIXELS, &m) != 0)
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

/* Grey levels in [0, 1] of a decoded Mat, row by row (no float copy of the whole image). */
static float *grey_from_mat(const cv::Mat &m)
{
    double scale = 1.0;
    if (m.depth() == CV_8U)
        scale = 1.0 / 255.0;
    else if (m.depth() == CV_16U)
        scale = 1.0 / 65535.0;
    int channels = m.channels();
    /* Colour is averaged over R, G, B (alpha, when present, is ignored). */
    int colour = channels >= 3 ? 3 : 1;
    size_t n = (size_t)m.cols * (size_t)m.rows;
    float *g = (float *)fs_malloc(n * sizeof(float));
    cv::Mat row_f;
    for (int y = 0; y < m.rows; y++) {
        m.row(y).convertTo(row_f, CV_MAKETYPE(CV_32F, channels), scale);
        const float *row = row_f.ptr<float>(0);
        for (int x = 0; x < m.cols; x++) {
            double sum = 0.0;
            for (int c = 0; c < colour; c++)
                sum += row[(size_t)x * (size_t)channels + (size_t)c];
            g[(size_t)y * (size_t)m.cols + (size_t)x] = (float)(sum / colour);
        }
    }
    return g;
}

static int decode_grey(const std::vector<unsigned char> &bytes, const char *origin, int *width, int *height,
                       float **grey)
{
    try {
        cv::Mat m;
        if (decode_bytes(bytes, origin, FS_IMAGE_MAX_MAP_PIXELS, &m) != 0)
            return -1;
        *grey = grey_from_mat(m);
        *width = m.cols;
        *height = m.rows;
        return 0;
    } catch (const cv::Exception &e) {
        fs_error(FS_ERR_DATA, "%s: cannot decode image: %s", origin, e.what());
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot decode image: %s", origin, e.what());
    }
    return -1;
}

extern "C" int fs_image_read_grey(const char *path, int *width, int *height, float **grey)
{
    try {
        std::vector<unsigned char> bytes;
        if (read_bytes(path, &bytes) != 0)
            return -1;
        return decode_grey(bytes, path, width, height, grey);
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot read image: %s", path, e.what());
    }
    return -1;
}

extern "C" int fs_image_decode_grey(const unsigned char *data, size_t n, const char *origin, int *width, int *height,
                                    float **grey)
{
    try {
        std::vector<unsigned char> bytes(data, data + n);
        return decode_grey(bytes, origin, width, height, grey);
    } catch (const std::exception &e) {
        fs_error(FS_ERR_INTERNAL, "%s: cannot decode image: %s", origin, e.what());
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
        /* PNG is encoded in memory and written here, so that a failed write says why (libpng's
         * own writer only printed "libpng error: Write Error"). OpenEXR has no memory encoder in
         * OpenCV: it writes the file itself, and its failure is reported with errno as the failed
         * write left it. */
        stderr_capture capture;
        if (png) {
            std::vector<unsigned char> bytes;
            bool encoded = cv::imencode(".png", m, bytes, params) && (tag != FS_IMAGE_SRGB || insert_srgb_chunk(bytes));
            std::string said = capture.restore();
            if (!encoded) {
                fs_error(FS_ERR_INTERNAL, "%s: cannot encode PNG%s%s", path, said.empty() ? "" : ": ", said.c_str());
                return -1;
            }
            return write_bytes(path, bytes);
        }
        errno = 0;
        bool written = cv::imwrite(path, m, params);
        int err = errno;
        std::string said = capture.restore();
        if (!written) {
            fs_error(FS_ERR_IO, "%s: cannot write image: %s%s%s", path, strerror(err ? err : EIO),
                     said.empty() ? "" : "; ", said.c_str());
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
