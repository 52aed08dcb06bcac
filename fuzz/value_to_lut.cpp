// The value -> LUT map (ValueToLut, include/lacuna/transfer_function.h) with arbitrary voxels,
// ranges and LUT sizes, through the boundary that guards it and the cell ranges that skipping
// rests on. Input, as raw bits (so NaN, Inf, denormals and FLT_MAX all occur):
//   8 floats     the corners of a 2x2x2 float32 volume (one cell)
//   1 byte       bit 0: override the visualization range with the next two floats (--range)
//   2 floats     that range
//   2 bytes      the LUT size, 2 + n % 4095
//   2 floats     two values for the totality and monotony checks
//   then         sample positions in the cell (3 x 16 bits each)
// Invariants:
//   - any range, even one the boundary rejects: map(v) is in [0, size-1] for every finite v,
//     and monotone (v1 <= v2 => map(v1) <= map(v2));
//   - a volume Volume::compute_range accepts gives finite trilinear samples (the kernel's
//     trilinear()), and with a range check_lut_range accepts every sample's entry lies in the
//     cell's range from cell_ranges.h (what exact skipping rests on).
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "accel/cell_ranges.h"
#include "fuzz_util.h"
#include "lacuna/transfer_function.h"
#include "render/ray_march_kernel.h"

using namespace lacuna;
using fuzz::fuzz_check;

namespace {

// The input read front to back, little-endian; zeros once it runs out.
struct Input {
    const uint8_t* p;
    size_t n;
    template <class T>
    T take() {
        T v{};
        if (n >= sizeof(T)) {
            std::memcpy(&v, p, sizeof(T));
            p += sizeof(T);
            n -= sizeof(T);
        } else {
            n = 0;
        }
        return v;
    }
    size_t remaining_bytes() const { return n; }
};

float raw_float(Input& in) {
    return std::bit_cast<float>(in.take<uint32_t>());
}

std::string text(float a, float b) {
    return std::to_string(a) + " " + std::to_string(b);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Input in{data, size};
    Volume v(Vec3i{2, 2, 2}, VoxelType::Float32, "fuzz");
    float* voxels = v.data_as<float>();
    for (int i = 0; i < 8; ++i) voxels[i] = raw_float(in);
    const bool override_range = in.take<uint8_t>() & 1;
    const ValueRange user{raw_float(in), raw_float(in)};
    const int lut_size = 2 + in.take<uint16_t>() % 4095;

    // 1. Totality and monotony for an arbitrary range (what a range no boundary checked gives).
    {
        const ValueToLut map(user, lut_size);
        const float a = raw_float(in), b = raw_float(in);
        if (std::isfinite(a) && std::isfinite(b)) {
            const int ea = map(a), eb = map(b);
            fuzz_check(ea >= 0 && ea < lut_size && eb >= 0 && eb < lut_size, "entry in range",
                       text(a, b));
            if (a <= b) fuzz_check(ea <= eb, "monotone", text(a, b));
        }
    }

    // 2. The volume boundary, then samples against the cell's range.
    try {
        v.compute_range("fuzz");
        if (override_range) v.set_vis_range(user);
        check_lut_range(v.vis_range(), lut_size, "fuzz", "range");
    } catch (const Error&) {
        return 0;
    }
    const ValueToLut map(v.vis_range(), lut_size);
    int lo = -1, hi = -1;
    for_each_block_cells(v, map, 1, 1, [&](const BlockCells& b) {
        lo = b.lo[0];
        hi = b.hi[0];
    });
    fuzz_check(lo >= 0 && lo <= hi && hi < lut_size, "cell range", text(float(lo), float(hi)));
    const auto grid = kernel::make_grid(voxels, v.dims());
    while (in.remaining_bytes() >= 6) {
        const float x = float(in.take<uint16_t>()) / 65535.f;
        const float y = float(in.take<uint16_t>()) / 65535.f;
        const float z = float(in.take<uint16_t>()) / 65535.f;
        const float s = kernel::trilinear(grid, x, y, z);
        fuzz_check(std::isfinite(s), "finite sample", std::to_string(s));
        const int e = map(s);
        fuzz_check(e >= lo && e <= hi, "sample entry within the cell's range",
                   std::to_string(e) + " not in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "], sample " + std::to_string(s));
    }
    return 0;
}
