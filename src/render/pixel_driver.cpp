#include "render/pixel_driver.h"

namespace lacuna {

void write_pixel(RenderResult& out, const RenderOptions& opt, int x, int y,
                 const kernel::Accum& acc, uint32_t samples) {
    const float w = 1.f - acc.a;
    uint8_t* px = out.image.pixel(x, y);
    const float rgb[3] = {acc.r + w * opt.background.x, acc.g + w * opt.background.y,
                          acc.b + w * opt.background.z};
    for (int c = 0; c < 3; ++c) {
        // std::lround for x in [0, 255] without the libm call: x - trunc(x) is exact there,
        // so the half-away-from-zero test is exact too.
        const float x = std::clamp(rgb[c], 0.f, 1.f) * 255.f;
        const int v = int(x);
        px[c] = uint8_t(v + int(x - float(v) >= 0.5f));
    }
    px[3] = 255;
    const size_t p = size_t(y) * size_t(out.image.width) + size_t(x);
    if (opt.keep_float) {
        float* f = &out.rgba_float[p * 4];
        f[0] = acc.r, f[1] = acc.g, f[2] = acc.b, f[3] = acc.a;
    }
    if (opt.count_samples) out.sample_counts[p] = samples;
}

}  // namespace lacuna
