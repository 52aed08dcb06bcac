#include "partition_boxes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/parallel.h"
#include "io/io_util.h"
#include "lacuna/camera.h"
#include "lacuna/error.h"
#include "lacuna/image.h"
#include "lacuna/orientation.h"
#include "lacuna/transfer_function.h"
#include "slice/growing_boxes_source.h"

namespace lacuna::cli {

namespace {

double ms(double s) {
    return std::round(s * 1e6) / 1e3;
}
double round6(float x) {
    return std::round(double(x) * 1e6) / 1e6;
}

template <class T>
T median(std::vector<T> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// ---- the picture (Figure 2): a z slice with the boxes crossing it outlined by type -----------

struct Rgb {
    uint8_t r, g, b;
};
// The paper's colours: red uniform, blue gradient, green other (indexed by BoxType).
constexpr Rgb kTypeColour[3] = {{235, 50, 50}, {70, 120, 255}, {40, 200, 60}};

// How the picture lies in the anatomy (issue 14): the slice is across the index axis nearest the
// patient's superior-inferior axis (an axial slice), seen from above with the patient's right to
// the right of the screen and anterior up. The panel's columns and rows follow the index axes
// nearest RAS x and y, reversed where they point left or posterior, so the same anatomy stored
// in another voxel order (RAS, LPS, a permuted order) gives the same slice picture. A volume
// without geometry is RAS: x right, y up, z the slice, as before orientation existed.
struct SliceAxes {
    int u = 0, v = 1, s = 2;  // index axes: screen right, screen up, across
    bool flip_u = false, flip_v = false, flip_s = false;  // reversed against RAS +x, +y, +z
};
SliceAxes slice_axes(const Volume& vol) {
    const Affine a = index_to_world(vol);
    SliceAxes ax;
    auto nearest = [&](int row, const bool* taken) {  // the free index axis most along RAS `row`
        int best = -1;
        for (int c = 0; c < 3; ++c)
            if (!taken[c] && (best < 0 || std::abs(a.m[row][c]) / a.column_length(c) >
                                              std::abs(a.m[row][best]) / a.column_length(best)))
                best = c;
        return best;
    };
    bool taken[3] = {false, false, false};
    ax.s = nearest(2, taken);
    taken[ax.s] = true;
    ax.u = nearest(0, taken);
    taken[ax.u] = true;
    ax.v = nearest(1, taken);
    ax.flip_s = a.m[2][ax.s] < 0;
    ax.flip_u = a.m[0][ax.u] < 0;
    ax.flip_v = a.m[1][ax.v] < 0;
    return ax;
}

struct Panel {
    Image& img;
    int x0, scale, cu, cv;  // panel origin in the image, pixels per cell, cells along u and v
    SliceAxes ax;
    void px(int x, int y, Rgb c) const {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        uint8_t* p = img.pixel(x, y);
        p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
    }
    // Screen coordinates (0..cu right, 0..cv up) of index coordinates along u and v.
    int su(int i) const { return ax.flip_u ? cu - i : i; }
    int sv(int j) const { return ax.flip_v ? cv - j : j; }
    // Screen cell coordinates to pixels; y up.
    int X(int x) const { return x0 + x * scale; }
    int Y(int y) const { return (cv - y) * scale; }
    // A box's extent on the screen: [lo, hi] in screen cell coordinates along u and v.
    void extent(const CellBox& b, int& ua, int& ub, int& va, int& vb) const {
        ua = std::min(su(b.lo[ax.u]), su(b.hi[ax.u]));
        ub = std::max(su(b.lo[ax.u]), su(b.hi[ax.u]));
        va = std::min(sv(b.lo[ax.v]), sv(b.hi[ax.v]));
        vb = std::max(sv(b.lo[ax.v]), sv(b.hi[ax.v]));
    }
    void rect(const CellBox& b, Rgb c) const {
        int ua, ub, va, vb;
        extent(b, ua, ub, va, vb);
        const int xa = X(ua), xb = std::max(X(ub) - 1, xa);
        const int ya = Y(vb), yb = std::max(Y(va) - 1, ya);
        for (int x = xa; x <= xb; ++x) px(x, ya, c), px(x, yb, c);
        for (int y = ya; y <= yb; ++y) px(xa, y, c), px(xb, y, c);
    }
    // Tints a box's inside dark violet (boxes the source skips under the TF).
    void tint(const CellBox& b) const {
        int ua, ub, va, vb;
        extent(b, ua, ub, va, vb);
        for (int y = Y(vb); y < Y(va); ++y)
            for (int x = X(ua); x < X(ub); ++x) {
                if (x < 0 || y < 0 || x >= img.width || y >= img.height) continue;
                uint8_t* p = img.pixel(x, y);
                p[0] = uint8_t((p[0] + 90) / 3), p[1] = uint8_t(p[1] / 3),
                p[2] = uint8_t((p[2] + 200) / 3);
            }
    }
};

// `k`: the cell layer across ax.s, in index order.
Image figure2(const Volume& vol, const GrowingBoxesSource& src, const SliceAxes& ax, int k,
              int size) {
    const Vec3i d = vol.dims();
    const int cu = d[ax.u] - 1, cv = d[ax.v] - 1;
    const int scale = std::max(1, size / std::max(cu, cv));
    const int gap = 8;
    Image img(2 * cu * scale + gap + 1, cv * scale + 1);
    for (size_t i = 0; i < img.rgba.size(); i += 4)
        img.rgba[i] = img.rgba[i + 1] = img.rgba[i + 2] = 0, img.rgba[i + 3] = 255;
    const ValueRange vis = vol.vis_range();
    const Panel left{img, 0, scale, cu, cv, ax}, right{img, cu * scale + gap, scale, cu, cv, ax};
    // The voxel plane on the layer's inferior side in grey (the visualization range), nearest
    // voxel per pixel: index plane k, or k + 1 when the axis runs downward.
    for (const Panel* p : {&left, &right})
        for (int y = 0; y < cv * scale; ++y)
            for (int x = 0; x < cu * scale; ++x) {
                int idx[3];
                idx[ax.s] = ax.flip_s ? k + 1 : k;
                idx[ax.u] = p->su(std::min(cu, (x + scale / 2) / scale));
                idx[ax.v] = p->sv(cv - (y + scale / 2) / scale);
                const float t =
                    (vol.value(idx[0], idx[1], idx[2]) - vis.min) / std::max(vis.width(), 1e-30f);
                const uint8_t g = uint8_t(std::clamp(t, 0.f, 1.f) * 200.f);
                p->px(p->x0 + x, y, Rgb{g, g, g});
            }
    auto crosses = [&](const CellBox& b) { return b.lo[ax.s] <= k && k < b.hi[ax.s]; };
    // (a) the grown boxes.
    for (const BoxInfo& b : src.grown())
        if (crosses(b.box)) left.rect(b.box, kTypeColour[int(b.type)]);
    // (b) the BSP leaves after merging; those empty under the TF are tinted.
    for (int32_t id : src.leaves()) {
        const CellBox& b = src.tree().boxes()[size_t(id)].box;
        if (crosses(b) && src.empty(id)) right.tint(b);
    }
    for (int32_t id : src.leaves()) {
        const CellBox& b = src.tree().boxes()[size_t(id)].box;
        if (crosses(b)) right.rect(b, kTypeColour[int(src.info(id).type)]);
    }
    return img;
}

nlohmann::json box_json(const CellBox& b) {
    return {{"lo", {b.lo[0], b.lo[1], b.lo[2]}},
            {"hi", {b.hi[0], b.hi[1], b.hi[2]}},
            {"cells", box_volume(b)}};
}

}  // namespace

void run_partition_boxes(const PartitionBoxesArgs& a, const Volume& vol) {
    validate(a.options);
    if (a.repeat < 1 || a.repeat > 1000) throw Error("--repeat", "repeat", "expected 1..1000");
    const Vec3i d = vol.dims();
    // --slice counts axial cell layers from the inferior end (the same anatomy in any voxel
    // order); k is the layer in index order.
    const SliceAxes ax = slice_axes(vol);
    const int layers = d[ax.s] - 1;
    const int slice = a.slice < 0 ? layers / 2 : a.slice;
    if (slice >= layers)
        throw Error("--slice", "cell layer",
                    "expected 0.." + std::to_string(layers - 1) + ", got " + std::to_string(slice));
    const int k = ax.flip_s ? layers - 1 - slice : slice;
    const TransferFunction tf = resolve_transfer_function(a.tf);
    const TransferLut lut = discretise(tf, vol.vis_range());

    // Builds `repeat` times (median step times), then the TF classification 101 times.
    std::unique_ptr<GrowingBoxesSource> src;
    std::vector<BoxesBuildStats> runs;
    for (int r = 0; r < a.repeat; ++r) {
        src = std::make_unique<GrowingBoxesSource>(vol, a.options);
        runs.push_back(src->stats());
    }
    std::vector<double> classify;
    for (int r = 0; r < 101; ++r) {
        src->set_transfer_function(lut);
        classify.push_back(src->stats().classify);
    }
    auto med = [&](double BoxesBuildStats::*f) {
        std::vector<double> v;
        for (const BoxesBuildStats& s : runs) v.push_back(s.*f);
        return median(v);
    };
    std::vector<double> totals;
    for (const BoxesBuildStats& s : runs) totals.push_back(s.total());
    const BoxesBuildStats& s = src->stats();
    const double t_grad = med(&BoxesBuildStats::gradient), t_grow = med(&BoxesBuildStats::grow),
                 t_split = med(&BoxesBuildStats::split), t_merge = med(&BoxesBuildStats::merge),
                 t_measure = med(&BoxesBuildStats::measure),
                 t_ranges = med(&BoxesBuildStats::ranges), t_total = median(totals),
                 t_classify = median(classify);

    // Visibility order for the default view (the same orbit camera as the kd-tree overlay).
    OrbitParams op;
    op.azimuth_deg = a.azimuth;
    op.elevation_deg = a.elevation;
    const Camera cam =
        to_volume_frame(volume_frame(vol), Camera::orbit(world_bounds(vol), op, 64, 64));
    const Vec3f eye{float(cam.eye().x / vol.spacing.x), float(cam.eye().y / vol.spacing.y),
                    float(cam.eye().z / vol.spacing.z)};

    uint64_t visible_cells = 0;
    for (int32_t id : src->leaves())
        if (!src->empty(id))
            visible_cells += uint64_t(box_volume(src->tree().boxes()[size_t(id)].box));
    const uint64_t total_cells = uint64_t(d.x - 1) * uint64_t(d.y - 1) * uint64_t(d.z - 1);

    std::printf("%s: %dx%dx%d, growing boxes + orthogonal BSP tree, TF %s\n", a.volume_path.c_str(),
                d.x, d.y, d.z, tf.name.c_str());
    std::printf("settings: %s, %d threads\n", to_string(a.options).c_str(),
                resolve_threads(a.options.threads));
    std::printf("boxes grown: %zu (uniform %zu, gradient %zu, other %zu)\n", s.grown,
                s.grown_by_type[0], s.grown_by_type[1], s.grown_by_type[2]);
    std::printf(
        "after BSP splits: %zu (depth %d); after merges: %zu (uniform %zu, gradient %zu, "
        "other %zu); sub-volumes (parents kept): %zu\n",
        s.after_split, s.depth, s.after_merge, s.final_by_type[0], s.final_by_type[1],
        s.final_by_type[2], s.sub_volumes);
    std::printf("empty under TF: %zu of %zu boxes; visible boxes hold %.1f%% of the cells\n",
                s.empty, s.after_merge, 100.0 * double(visible_cells) / double(total_cells));
    std::printf(
        "build%s: gradient %.1f ms, grow %.1f ms, split %.1f ms, measure %.1f ms, merge %.1f ms, "
        "ranges %.1f ms (total %.1f ms); TF classification %.3f ms (median of 101)\n",
        a.repeat > 1 ? (" (median of " + std::to_string(a.repeat) + ")").c_str() : "", t_grad * 1e3,
        t_grow * 1e3, t_split * 1e3, t_measure * 1e3, t_merge * 1e3, t_ranges * 1e3, t_total * 1e3,
        t_classify * 1e3);

    if (!a.json.empty()) {
        nlohmann::json j;
        j["volume"] = a.volume_path;
        j["dims"] = {d.x, d.y, d.z};
        j["cells"] = {d.x - 1, d.y - 1, d.z - 1};
        j["spacing"] = {vol.spacing.x, vol.spacing.y, vol.spacing.z};
        j["method"] = "boxes";
        j["tf"] = tf.name;
        const BoxesOptions& o = a.options;
        j["settings"] = {{"spread_256ths", round6(o.spread)},
                         {"min_box", o.min_uniform},
                         {"gradient", round6(o.gradient)},
                         {"gradient_waste", round6(o.gradient_waste)},
                         {"other_cost", round6(o.other_cost)},
                         {"thin", o.thin},
                         {"merge", o.merge},
                         {"threads", resolve_threads(o.threads)}};
        j["timings_ms"] = {{"gradient", ms(t_grad)},     {"grow", ms(t_grow)},
                           {"split", ms(t_split)},       {"measure", ms(t_measure)},
                           {"merge", ms(t_merge)},       {"ranges", ms(t_ranges)},
                           {"build_total", ms(t_total)}, {"tf_classification", ms(t_classify)},
                           {"repeat", a.repeat}};
        j["counts"] = {{"grown", s.grown},
                       {"grown_uniform", s.grown_by_type[0]},
                       {"grown_gradient", s.grown_by_type[1]},
                       {"grown_other", s.grown_by_type[2]},
                       {"after_split", s.after_split},
                       {"after_merge", s.after_merge},
                       {"final_uniform", s.final_by_type[0]},
                       {"final_gradient", s.final_by_type[1]},
                       {"final_other", s.final_by_type[2]},
                       {"empty_under_tf", s.empty},
                       {"sub_volumes", s.sub_volumes},
                       {"depth", s.depth},
                       {"lut_intervals", s.intervals}};
        j["total_cells"] = total_cells;
        j["visible_cells"] = visible_cells;
        j["view"] = {{"azimuth", a.azimuth},
                     {"elevation", a.elevation},
                     {"eye_index", {eye.x, eye.y, eye.z}}};
        j["box_coordinates"] = "voxel index: a box spans voxels lo..hi (cells [lo, hi))";
        nlohmann::json grown = nlohmann::json::array();
        for (const BoxInfo& b : src->grown()) {
            nlohmann::json e = box_json(b.box);
            e["type"] = to_string(b.type);
            grown.push_back(e);
        }
        j["grown_boxes"] = grown;
        // Every final leaf, front to back for the view; "empty" ones are skipped by the source.
        std::vector<int32_t> order;
        src->tree().order(eye, order);
        nlohmann::json list = nlohmann::json::array();
        for (int32_t id : order) {
            nlohmann::json e = box_json(src->tree().boxes()[size_t(id)].box);
            e["type"] = to_string(src->info(id).type);
            e["empty"] = src->empty(id);
            e["parent"] = src->tree().parent_of(id);
            list.push_back(e);
        }
        j["boxes"] = list;
        io::write_text_atomic(a.json, j.dump(1) + "\n");
        std::printf("wrote %s\n", a.json.c_str());
    }
    if (!a.out.empty()) {
        const Image img = figure2(vol, *src, ax, k, a.size);
        write_png(a.out, img);
        std::printf(
            "wrote %s (%dx%d, axial slice %d from inferior = index %c %d, seen from above, "
            "patient's right to the right: grown boxes left, BSP leaves right; red uniform, blue "
            "gradient, green other; tinted violet: empty under the TF)\n",
            a.out.c_str(), img.width, img.height, slice, "xyz"[ax.s], k);
    }
}

}  // namespace lacuna::cli
