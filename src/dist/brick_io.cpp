#include "dist/brick_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "lacuna/error.h"

namespace lacuna::dist {

Volume crop_brick(const Volume& whole, Vec3i offset, Vec3i dims) {
    const Vec3i wd = whole.dims();
    for (int a = 0; a < 3; ++a)
        if (offset[a] < 0 || dims[a] < 2 || offset[a] + dims[a] > wd[a])
            throw Error("brick", "voxels", "expected a brick inside the volume");
    Volume b(dims, whole.type(), "brick");
    const size_t vs = voxel_size(whole.type());
    const auto* src = static_cast<const uint8_t*>(whole.data());
    auto* dst = static_cast<uint8_t*>(b.data());
    const size_t row = size_t(dims.x) * vs;
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            std::memcpy(dst + b.index(0, j, k) * vs,
                        src + whole.index(offset.x, offset.y + j, offset.z + k) * vs, row);
    b.spacing = whole.spacing;
    b.origin = whole.origin;
    std::copy_n(whole.direction, 9, b.direction);
    b.geometry_source = whole.geometry_source;
    b.compute_range("brick");
    b.set_vis_range(whole.vis_range());
    return b;
}

}  // namespace lacuna::dist

namespace lacuna::dist {

void finite_minmax(const Volume& v, float& lo, float& hi) {
    lo = std::numeric_limits<float>::infinity(), hi = -lo;
    const size_t n = v.voxel_count();
    visit_voxels(v, [&](const auto* p) {
        for (size_t i = 0; i < n; ++i) {
            const float x = float(p[i]);
            if (std::isnan(x)) continue;
            lo = std::min(lo, x), hi = std::max(hi, x);
        }
    });
}

size_t replace_nan(Volume& v, float value) {
    if (v.type() != VoxelType::Float32) return 0;
    float* p = v.data_as<float>();
    size_t n = 0;
    for (size_t i = 0; i < v.voxel_count(); ++i)
        if (std::isnan(p[i])) p[i] = value, ++n;
    v.nan_voxels = n;
    return n;
}

ValueRange default_vis_range(float lo, float hi) {
    Volume v({2, 2, 2}, VoxelType::Float32, "range");
    for (int i = 0; i < 8; ++i) v.data_as<float>()[i] = i == 0 ? hi : lo;
    v.compute_range("range");
    return v.vis_range();
}

}  // namespace lacuna::dist
