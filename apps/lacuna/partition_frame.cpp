#include "partition_frame.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "accel/summed_volume_table.h"
#include "lacuna/orientation.h"

namespace lacuna::cli {

RasOrder ras_order(const Volume& v) {
    const Affine a = index_to_world(v);
    // The free file axis most along RAS axis `row` (by the cosine; ties to the lower axis).
    bool taken[3] = {false, false, false};
    auto nearest = [&](int row) {
        int best = -1;
        double best_cos = -1;
        for (int c = 0; c < 3; ++c) {
            if (taken[c]) continue;
            const double cos = std::abs(a.m[row][c]) / a.column_length(c);
            if (cos > best_cos) best = c, best_cos = cos;
        }
        taken[best] = true;
        return best;
    };
    RasOrder o;
    o.axis[2] = nearest(2);  // superior first: the axial slices of the boxes figure
    o.axis[0] = nearest(0);
    o.axis[1] = nearest(1);
    for (int r = 0; r < 3; ++r) o.flip[size_t(r)] = a.m[r][o.axis[size_t(r)]] < 0;
    return o;
}

Volume reorder(const Volume& v, const RasOrder& o) {
    const Vec3i d = v.dims();
    Vec3i n;
    for (int a = 0; a < 3; ++a) n[a] = d[o.axis[size_t(a)]];
    Volume out(n, v.type(), "partition");
    // File voxel of RAS-order voxel (i,j,k): index = base + i*step[0] + j*step[1] + k*step[2].
    const int64_t file_stride[3] = {1, int64_t(d.x), int64_t(d.x) * int64_t(d.y)};
    int64_t step[3], base = 0;
    for (int a = 0; a < 3; ++a) {
        const int c = o.axis[size_t(a)];
        step[a] = o.flip[size_t(a)] ? -file_stride[c] : file_stride[c];
        if (o.flip[size_t(a)]) base += int64_t(d[c] - 1) * file_stride[c];
    }
    visit_voxels(v, [&](const auto* src) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(src)>>;
        T* dst = out.data_as<T>();
        size_t at = 0;
        for (int k = 0; k < n.z; ++k)
            for (int j = 0; j < n.y; ++j) {
                const int64_t row = base + int64_t(k) * step[2] + int64_t(j) * step[1];
                for (int i = 0; i < n.x; ++i) dst[at++] = src[row + int64_t(i) * step[0]];
            }
    });
    // Geometry in the LPS form Volume keeps: column a is +-column axis[a]; a reversed axis
    // starts at the file's last voxel along it.
    out.origin = v.origin;
    for (int a = 0; a < 3; ++a) {
        const int c = o.axis[size_t(a)];
        const double s = o.flip[size_t(a)] ? -1.0 : 1.0;
        out.spacing[a] = v.spacing[c];
        for (int r = 0; r < 3; ++r) {
            out.direction[r * 3 + a] = s * v.direction[r * 3 + c] + 0.0;
            if (o.flip[size_t(a)])
                out.origin[r] += double(d[c] - 1) * v.spacing[c] * v.direction[r * 3 + c];
        }
    }
    out.geometry_source = v.geometry_source;
    out.compute_range("partition");  // the same voxels: the same data range
    const ValueRange vis = v.vis_range();
    if (out.vis_range().min != vis.min || out.vis_range().max != vis.max) out.set_vis_range(vis);
    return out;
}

CellBox to_file_cells(const CellBox& b, const RasOrder& o, Vec3i file_dims) {
    CellBox f{};
    for (int a = 0; a < 3; ++a) {
        const int c = o.axis[size_t(a)], cells = file_dims[c] - 1;
        f.lo[c] = o.flip[size_t(a)] ? cells - b.hi[a] : b.lo[a];
        f.hi[c] = o.flip[size_t(a)] ? cells - b.lo[a] : b.hi[a];
    }
    return f;
}

Vec3f to_file_index(Vec3f p, const RasOrder& o, Vec3i file_dims) {
    Vec3f f{};
    for (int a = 0; a < 3; ++a) {
        const int c = o.axis[size_t(a)];
        f[c] = o.flip[size_t(a)] ? float(file_dims[c] - 1) - p[a] : p[a];
    }
    return f;
}

void world_box(const Volume& v, const CellBox& b, double lo[3], double hi[3]) {
    const Affine a = index_to_world(v);
    for (int r = 0; r < 3; ++r) lo[r] = INFINITY, hi[r] = -INFINITY;
    for (int m = 0; m < 8; ++m) {
        const Vec3d w =
            a.apply({double(m & 1 ? b.hi[0] : b.lo[0]), double(m & 2 ? b.hi[1] : b.lo[1]),
                     double(m & 4 ? b.hi[2] : b.lo[2])});
        for (int r = 0; r < 3; ++r) lo[r] = std::min(lo[r], w[r]), hi[r] = std::max(hi[r], w[r]);
    }
}

std::string to_string(const RasOrder& o) {
    // "x = -i, y = -j, z = k": which file axis (reversed or not) each RAS-order axis is.
    std::string s;
    for (int a = 0; a < 3; ++a) {
        if (a) s += ", ";
        s += std::string(1, "xyz"[a]) + " = " + (o.flip[size_t(a)] ? "-" : "") +
             "ijk"[o.axis[size_t(a)]];
    }
    return s;
}

nlohmann::json box_json(const CellBox& box, const Volume& file, const RasOrder& o) {
    const CellBox b = to_file_cells(box, o, file.dims());
    double lo[3], hi[3];
    world_box(file, b, lo, hi);
    auto mm = [](double x) { return std::round(x * 1e6) / 1e6 + 0.0; };
    return {
        {"lo", {b.lo[0], b.lo[1], b.lo[2]}},
        {"hi", {b.hi[0], b.hi[1], b.hi[2]}},
        {"cells", box_volume(b)},
        {"world",
         {{"lo", {mm(lo[0]), mm(lo[1]), mm(lo[2])}}, {"hi", {mm(hi[0]), mm(hi[1]), mm(hi[2])}}}}};
}

}  // namespace lacuna::cli
