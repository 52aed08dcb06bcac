// PNG output/input with libpng, and the count heat map.
//
// libpng reports errors by longjmp. Jumping over C++ frames with destructors is undefined, so
// every setjmp lives in a function whose locals are plain pointers and ints, and the C++
// side (temporary file names, exceptions) stays outside it.
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "io/io_util.h"
#include "lacuna/error.h"
#include "lacuna/image.h"

namespace lacuna {

namespace {

// libpng error/warning hooks: keep the message for the exception, print nothing.
struct PngMessage {
    char text[200] = {};
};

void png_error_hook(png_structp png, png_const_charp msg) {
    auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
    if (m) std::snprintf(m->text, sizeof m->text, "%s", msg ? msg : "libpng error");
    png_longjmp(png, 1);
}

void png_warning_hook(png_structp, png_const_charp) {}

// Returns 0 on success; on failure `msg` holds libpng's reason.
int encode_png(FILE* fp, const Image& img, PngMessage& msg) {
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, &msg, png_error_hook, png_warning_hook);
    if (!png) return 1;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return 1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return 1;
    }
    png_init_io(png, fp);
    // Renders are noisy; level 6 is libpng's default balance of size and speed.
    png_set_compression_level(png, 6);
    png_set_IHDR(png, info, png_uint_32(img.width), png_uint_32(img.height), 8, PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < img.height; ++y)
        png_write_row(png, img.rgba.data() + size_t(y) * size_t(img.width) * 4);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return 0;
}

// Decodes to 8-bit RGBA into `out`; `rows` is scratch owned by the caller so a longjmp cannot
// leak it. Returns 0 on success.
int decode_png(FILE* fp, PngMessage& msg, Image* out, std::vector<png_bytep>* rows) {
    png_structp png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, &msg, png_error_hook, png_warning_hook);
    if (!png) return 1;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_read_struct(&png, nullptr, nullptr);
        return 1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return 1;
    }
    png_init_io(png, fp);
    png_read_info(png, info);
    const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    const int color = png_get_color_type(png, info);
    // Normalise everything to 8-bit RGBA.
    png_set_expand(png);
    png_set_strip_16(png);
    if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(png);
    if (!(color & PNG_COLOR_MASK_ALPHA)) png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    if (w == 0 || h == 0 || w > 65535 || h > 65535 || png_get_rowbytes(png, info) != w * 4) {
        std::snprintf(msg.text, sizeof msg.text, "unsupported size or layout %ux%u", unsigned(w),
                      unsigned(h));
        png_destroy_read_struct(&png, &info, nullptr);
        return 1;
    }
    // At most 65535^2*4 bytes. If the allocation throws, the png structs leak; acceptable for
    // a tests-and-comparisons reader.
    out->width = int(w);
    out->height = int(h);
    out->rgba.assign(size_t(w) * size_t(h) * 4, 0);
    rows->resize(h);
    for (png_uint_32 y = 0; y < h; ++y) (*rows)[y] = out->rgba.data() + size_t(y) * w * 4;
    png_read_image(png, rows->data());
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return 0;
}

}  // namespace

void write_png(const std::string& path, const Image& img) {
    if (img.width <= 0 || img.height <= 0 ||
        img.rgba.size() != size_t(img.width) * size_t(img.height) * 4)
        throw Error(path, "output",
                    "invalid image " + std::to_string(img.width) + "x" +
                        std::to_string(img.height) + " with " + std::to_string(img.rgba.size()) +
                        " bytes");
    io::check_writable_dir(path);
    const io::TempName tmp = io::temp_name_beside(path);
    io::remove_stale_temp_files(tmp.dir);
    FILE* fp = std::fopen(tmp.path.c_str(), "wb");
    if (!fp) throw Error(path, "output", std::string("cannot write: ") + std::strerror(errno));
    PngMessage msg;
    const int rc = encode_png(fp, img, msg);
    const int flush_errno = std::fflush(fp) != 0                    ? errno
                            : rc == 0 && ::fsync(::fileno(fp)) != 0 ? errno
                                                                    : 0;
    const bool io_error = std::ferror(fp) != 0;
    const int close_errno = std::fclose(fp) != 0 ? errno : 0;
    if (rc != 0 || io_error || flush_errno || close_errno) {
        std::remove(tmp.path.c_str());
        std::string why = msg.text[0] ? std::string(msg.text)
                                      : std::strerror(flush_errno   ? flush_errno
                                                      : close_errno ? close_errno
                                                                    : EIO);
        throw Error(path, "output", "cannot write: " + why);
    }
    if (std::rename(tmp.path.c_str(), path.c_str()) != 0) {
        const int e = errno;
        std::remove(tmp.path.c_str());
        throw Error(path, "output", std::string("cannot write: ") + std::strerror(e));
    }
    io::sync_dir(tmp.dir);
}

std::string png_bytes(const Image& img) {
    if (img.width <= 0 || img.height <= 0 ||
        img.rgba.size() != size_t(img.width) * size_t(img.height) * 4)
        throw Error(
            "png", "image",
            "invalid image " + std::to_string(img.width) + "x" + std::to_string(img.height));
    // open_memstream: a FILE over a growing buffer, so encode_png writes exactly what it writes
    // to a file. buf and size are valid after fclose.
    char* buf = nullptr;
    size_t size = 0;
    FILE* fp = ::open_memstream(&buf, &size);
    if (!fp) throw Error("png", "memory", std::string("cannot encode: ") + std::strerror(errno));
    PngMessage msg;
    const int rc = encode_png(fp, img, msg);
    const bool failed = std::fclose(fp) != 0 || rc != 0;
    std::string out = failed || !buf ? std::string() : std::string(buf, size);
    std::free(buf);
    if (failed)
        throw Error("png", "image",
                    std::string("cannot encode: ") + (msg.text[0] ? msg.text : "out of memory"));
    return out;
}

Image read_png(const std::string& path) {
    io::check_readable_file(path);
    FILE* fp = std::fopen(path.c_str(), "rb");
    if (!fp) throw Error(path, "file", std::string("cannot open: ") + std::strerror(errno));
    unsigned char sig[8] = {};
    const size_t n = std::fread(sig, 1, sizeof sig, fp);
    if (n != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0) {
        std::fclose(fp);
        throw Error(path, "header", "not a PNG file");
    }
    std::rewind(fp);
    Image img;
    PngMessage msg;
    std::vector<png_bytep> rows;
    const int rc = decode_png(fp, msg, &img, &rows);
    std::fclose(fp);
    if (rc != 0)
        throw Error(path, "image data",
                    io::one_line(msg.text[0] ? msg.text : "libpng could not decode the file"));
    return img;
}

Image heatmap(const std::vector<uint32_t>& counts, int width, int height, uint32_t max_count) {
    if (width <= 0 || height <= 0 || counts.size() != size_t(width) * size_t(height))
        throw Error("heatmap", "counts",
                    "expected " + std::to_string(std::max(width, 0)) + "x" +
                        std::to_string(std::max(height, 0)) + " counts, got " +
                        std::to_string(counts.size()));
    if (max_count == 0)
        for (uint32_t c : counts) max_count = std::max(max_count, c);
    // Stops of matplotlib's "inferno" (perceptually uniform, dark to bright) at 0, 1/7, ..,
    // 6/7, with the last stop pushed from inferno's pale yellow to white so the maximum reads
    // as white, as the heat map contract says.
    static constexpr uint8_t kStops[8][3] = {{0, 0, 4},      {40, 11, 84},   {101, 21, 110},
                                             {159, 42, 99},  {212, 72, 66},  {245, 125, 21},
                                             {250, 193, 39}, {255, 255, 255}};
    Image img(width, height);
    for (size_t i = 0; i < counts.size(); ++i) {
        uint8_t* p = &img.rgba[i * 4];
        p[3] = 255;
        if (counts[i] == 0 || max_count == 0) continue;  // zero is pure black
        const double t = std::min(1.0, double(counts[i]) / double(max_count)) * 7.0;
        const int k = std::min(6, int(t));
        const double f = t - double(k);
        for (int c = 0; c < 3; ++c)
            p[c] = uint8_t(std::lround(kStops[k][c] + f * (kStops[k + 1][c] - kStops[k][c])));
    }
    return img;
}

}  // namespace lacuna
