// 8-bit RGBA images and PNG output.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace lacuna {

struct Image {
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;  // row-major, top row first, 4 bytes per pixel
    Image() = default;
    Image(int w, int h) : width(w), height(h), rgba(size_t(w) * size_t(h) * 4, 0) {}
    uint8_t* pixel(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
    const uint8_t* pixel(int x, int y) const {
        return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
    }
};

// Writes a PNG atomically: to a temporary file beside `path`, then renamed over it, so a
// failure never leaves a partial file. Throws lacuna::Error(path, "output", reason).
void write_png(const std::string& path, const Image& img);
// The bytes write_png writes for `img`, in memory (the viewer's screenshot: the same encoder and
// settings, so a screenshot equals `lacuna render`'s PNG byte for byte). Throws lacuna::Error.
std::string png_bytes(const Image& img);
// Reads an 8-bit RGB/RGBA PNG (tests, comparisons). Throws lacuna::Error on failure.
Image read_png(const std::string& path);

// Per-pixel counts as a heat map (the bitfield paper's Figure 5): 0 is black, max_count (or
// the largest count when 0) is white, through a perceptual colour ramp.
Image heatmap(const std::vector<uint32_t>& counts, int width, int height, uint32_t max_count = 0);

}  // namespace lacuna
