// The specular power x^power of Blinn-Phong shading (render/shading.h), shared by the scalar
// reference and the lane kernels (core/simd_shading.h) so that both compute the same bits.
#pragma once
#include <cmath>

namespace lacuna::simd {

// x^power for the specular lobe. An integer power 1..256 (the usual case: Slicer and VTK
// presets use 1..100, lacuna's default is 24) is binary exponentiation: square b = x, b^2, b^4,
// ... and multiply the result by the squares of the power's set bits, low bit first (r starts
// at 1, and 1 * b == b exactly). Every kernel path does exactly these multiplies in this order
// (core/simd_shading.h spec_pow8), so the bits agree, and it costs a few multiplies instead of
// a libm call; the result is within 2*power ulps of the exact power (each squaring doubles the
// relative error it inherits: < 3e-6 for 24, invisible at 8 bits). Any other power: std::pow.
inline bool integer_power(float power) {
    return power >= 1.f && power <= 256.f && power == float(int(power));
}
inline float spec_pow(float x, float power) {
    if (!integer_power(power)) return std::pow(x, power);
    float r = 1.f, b = x;
    for (int n = int(power);;) {
        if (n & 1) r = r * b;
        n >>= 1;
        if (!n) return r;
        b = b * b;
    }
}

}  // namespace lacuna::simd
