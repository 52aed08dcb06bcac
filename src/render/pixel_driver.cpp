#include "render/pixel_driver.h"

#include <cstring>
#if defined(__SSE4_1__)
#include <immintrin.h>
#endif

namespace lacuna {

// The RGBA8 word of `acc` over the background (pixel_word, pixel_driver.h).
static inline uint32_t word_of(const Vec3f& background, const kernel::Accum& acc) {
    const float w = 1.f - acc.a;
    const float rgb[3] = {acc.r + w * background.x, acc.g + w * background.y,
                          acc.b + w * background.z};
    // std::lround of clamp(c, 0, 1) * 255 per channel, for c in [0, 255] without the libm call:
    // x - trunc(x) is exact there, so the half-away-from-zero test is exact too. NaN becomes 0.
#if defined(__SSE4_1__)
    // (the same operations, three channels at once and without branches)
    const __m128 v = _mm_mul_ps(
        _mm_min_ps(_mm_max_ps(_mm_setr_ps(rgb[0], rgb[1], rgb[2], 1.f), _mm_setzero_ps()),
                   _mm_set1_ps(1.f)),
        _mm_set1_ps(255.f));
    const __m128i t = _mm_cvttps_epi32(v);
    const __m128i r = _mm_sub_epi32(
        t, _mm_castps_si128(_mm_cmpge_ps(_mm_sub_ps(v, _mm_cvtepi32_ps(t)), _mm_set1_ps(0.5f))));
    const __m128i b8 = _mm_packus_epi16(_mm_packus_epi32(r, r), _mm_setzero_si128());
    return uint32_t(_mm_cvtsi128_si32(b8));  // alpha: 1 * 255 = 255
#else
    uint8_t px[4];
    for (int c = 0; c < 3; ++c) {
        const float u = rgb[c] > 0.f ? rgb[c] : 0.f;
        const float x = (u < 1.f ? u : 1.f) * 255.f;
        const int v = int(x);
        px[c] = uint8_t(v + int(x - float(v) >= 0.5f));
    }
    px[3] = 255;
    uint32_t word;
    std::memcpy(&word, px, 4);
    return word;
#endif
}

uint32_t pixel_word(const Vec3f& background, const kernel::Accum& acc) {
    return word_of(background, acc);
}

uint32_t empty_pixel_word(const RenderOptions& opt) {
    return word_of(opt.background, kernel::Accum{});
}

void write_pixel(RenderResult& out, const RenderOptions& opt, int x, int y,
                 const kernel::Accum& acc, uint32_t samples) {
    const uint32_t word = word_of(opt.background, acc);
    std::memcpy(out.image.pixel(x, y), &word, 4);
    const size_t p = size_t(y) * size_t(out.image.width) + size_t(x);
    if (opt.keep_float) {
        float* f = &out.rgba_float[p * 4];
        f[0] = acc.r, f[1] = acc.g, f[2] = acc.b, f[3] = acc.a;
    }
    if (opt.count_samples) out.sample_counts[p] = samples;
}

}  // namespace lacuna
