#include "volume/resample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "core/parallel.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {

// Per output index on one axis: the input voxel below the sample and the weight of the one
// above (x = i0 + w, 0 <= w < 1; the last output voxel lands on the last input voxel with w = 0
// and i0 = n_in - 2, w = 1 would read past nothing either way).
struct AxisMap {
    std::vector<int> i0;
    std::vector<double> w;
};

AxisMap axis_map(int n_in, int n_out) {
    AxisMap m;
    m.i0.resize(size_t(n_out));
    m.w.resize(size_t(n_out));
    for (int i = 0; i < n_out; ++i) {
        // Exact rational position i * (n_in - 1) / (n_out - 1): integer part and remainder.
        const int64_t num = int64_t(i) * int64_t(n_in - 1);
        const int64_t den = int64_t(n_out - 1);
        int64_t base = num / den;
        int64_t rem = num % den;
        if (base >= n_in - 1) base = n_in - 2, rem = den;  // the last voxel: weight 1 above
        m.i0[size_t(i)] = int(base);
        m.w[size_t(i)] = double(rem) / double(den);
    }
    return m;
}

template <class T>
T store(double v) {
    if constexpr (std::is_floating_point_v<T>) {
        return T(v);
    } else {
        const double r = std::round(v);
        return T(std::clamp(r, double(std::numeric_limits<T>::min()),
                            double(std::numeric_limits<T>::max())));
    }
}

template <class T>
void resample_typed(const Volume& in, Volume& out, int threads) {
    const Vec3i di = in.dims(), d = out.dims();
    const AxisMap mx = axis_map(di.x, d.x), my = axis_map(di.y, d.y), mz = axis_map(di.z, d.z);
    const T* src = in.data_as<T>();
    T* dst = out.data_as<T>();
    const size_t sx = 1, sy = size_t(di.x), sz = size_t(di.x) * size_t(di.y);
    parallel_for(size_t(d.z), threads, [&](size_t k0, size_t k1) {
        for (size_t k = k0; k < k1; ++k) {
            const double wz = mz.w[k];
            for (int j = 0; j < d.y; ++j) {
                const double wy = my.w[size_t(j)];
                const T* base = src + size_t(mz.i0[k]) * sz + size_t(my.i0[size_t(j)]) * sy;
                T* row = dst + out.index(0, j, int(k));
                for (int i = 0; i < d.x; ++i) {
                    const double wx = mx.w[size_t(i)];
                    const T* p = base + size_t(mx.i0[size_t(i)]) * sx;
                    // Along x on the four edges, then y, then z.
                    const double c00 = double(p[0]) + wx * (double(p[sx]) - double(p[0]));
                    const double c10 = double(p[sy]) + wx * (double(p[sy + sx]) - double(p[sy]));
                    const double c01 = double(p[sz]) + wx * (double(p[sz + sx]) - double(p[sz]));
                    const double c11 =
                        double(p[sz + sy]) + wx * (double(p[sz + sy + sx]) - double(p[sz + sy]));
                    const double c0 = c00 + wy * (c10 - c00);
                    const double c1 = c01 + wy * (c11 - c01);
                    row[i] = store<T>(c0 + wz * (c1 - c0));
                }
            }
        }
    });
}

}  // namespace

Volume resample_trilinear(const Volume& in, Vec3i out_dims, int threads) {
    for (int a = 0; a < 3; ++a)
        if (out_dims[a] < 2 || out_dims[a] > kMaxDim)
            throw Error("resample", "dims",
                        "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                            std::to_string(out_dims.x) + "x" + std::to_string(out_dims.y) + "x" +
                            std::to_string(out_dims.z));
    Volume out(out_dims, in.type(), "resample");
    visit_voxels(in, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        resample_typed<T>(in, out, threads);
    });
    const Vec3i di = in.dims();
    out.spacing = {in.spacing.x * double(di.x - 1) / double(out_dims.x - 1),
                   in.spacing.y * double(di.y - 1) / double(out_dims.y - 1),
                   in.spacing.z * double(di.z - 1) / double(out_dims.z - 1)};
    out.origin = in.origin;
    std::copy(std::begin(in.direction), std::end(in.direction), std::begin(out.direction));
    out.compute_range("resample");
    if (in.vis_range().max > in.vis_range().min) out.set_vis_range(in.vis_range());
    return out;
}

}  // namespace lacuna
