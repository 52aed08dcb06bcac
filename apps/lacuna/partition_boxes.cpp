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
#include "partition_frame.h"
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

// How the picture lies in the anatomy (issue 14): everything here is built on the voxels in RAS
// order (partition_frame.h), so the slice is across the superior axis (an axial slice), seen from
// above with the patient's right to the right of the screen and anterior up: panel columns are
// index x, rows index y (up), the slice a z layer. The same anatomy in another voxel order (RAS,
// LPS, a permuted order) gives the same voxels there, hence the same boxes and the same picture.
// A volume without geometry is RAS already: x right, y up, z the slice, as before orientation
// existed.
struct Panel {
    Image& img;
    int x0, scale, cu, cv;  // panel origin in the image, pixels per cell, cells along x and y
    void px(int x, int y, Rgb c) const {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        uint8_t* p = img.pixel(x, y);
        p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
    }
    // Cell coordinates (0..cu right, 0..cv up) to pixels; y up.
    int X(int x) const { return x0 + x * scale; }
    int Y(int y) const { return (cv - y) * scale; }
    void rect(const CellBox& b, Rgb c) const {
        const int xa = X(b.lo[0]), xb = std::max(X(b.hi[0]) - 1, xa);
        const int ya = Y(b.hi[1]), yb = std::max(Y(b.lo[1]) - 1, ya);
        for (int x = xa; x <= xb; ++x) px(x, ya, c), px(x, yb, c);
        for (int y = ya; y <= yb; ++y) px(xa, y, c), px(xb, y, c);
    }
    // Tints a box's inside dark violet (boxes the source skips under the TF).
    void tint(const CellBox& b) const {
        for (int y = Y(b.hi[1]); y < Y(b.lo[1]); ++y)
            for (int x = X(b.lo[0]); x < X(b.hi[0]); ++x) {
                if (x < 0 || y < 0 || x >= img.width || y >= img.height) continue;
                uint8_t* p = img.pixel(x, y);
                p[0] = uint8_t((p[0] + 90) / 3), p[1] = uint8_t(p[1] / 3),
                p[2] = uint8_t((p[2] + 200) / 3);
            }
    }
};

// `vol` in RAS order, `src` built on it; `k`: the z cell layer (from the inferior end).
Image figure2(const Volume& vol, const GrowingBoxesSource& src, int k, int size) {
    const Vec3i d = vol.dims();
    const int cu = d.x - 1, cv = d.y - 1;
    const int scale = std::max(1, size / std::max(cu, cv));
    const int gap = 8;
    Image img(2 * cu * scale + gap + 1, cv * scale + 1);
    for (size_t i = 0; i < img.rgba.size(); i += 4)
        img.rgba[i] = img.rgba[i + 1] = img.rgba[i + 2] = 0, img.rgba[i + 3] = 255;
    const ValueRange vis = vol.vis_range();
    const Panel left{img, 0, scale, cu, cv}, right{img, cu * scale + gap, scale, cu, cv};
    // The voxel plane z = k (the layer's inferior side) in grey (the visualization range),
    // nearest voxel per pixel.
    for (const Panel* p : {&left, &right})
        for (int y = 0; y < cv * scale; ++y)
            for (int x = 0; x < cu * scale; ++x) {
                const float t = (vol.value(std::min(cu, (x + scale / 2) / scale),
                                           cv - (y + scale / 2) / scale, k) -
                                 vis.min) /
                                std::max(vis.width(), 1e-30f);
                const uint8_t g = uint8_t(std::clamp(t, 0.f, 1.f) * 200.f);
                p->px(p->x0 + x, y, Rgb{g, g, g});
            }
    auto crosses = [&](const CellBox& b) { return b.lo[2] <= k && k < b.hi[2]; };
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

}  // namespace

void run_partition_boxes(const PartitionBoxesArgs& a, const Volume& file) {
    validate(a.options);
    if (a.repeat < 1 || a.repeat > 1000) throw Error("--repeat", "repeat", "expected 1..1000");
    const Vec3i d = file.dims();
    // Everything below is built on the voxels in RAS order (partition_frame.h): the boxes, their
    // tree and the picture are then the same for the same anatomy in any voxel order. Only the
    // JSON's voxel coordinates go back to the file's index.
    const RasOrder order = ras_order(file);
    const Volume vol = order.identity() ? file : reorder(file, order);
    // --slice counts axial cell layers from the inferior end: the z layer of the RAS order.
    const int layers = vol.dims().z - 1;
    const int slice = a.slice < 0 ? layers / 2 : a.slice;
    if (slice >= layers)
        throw Error("--slice", "cell layer",
                    "expected 0.." + std::to_string(layers - 1) + ", got " + std::to_string(slice));
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
        to_volume_frame(volume_frame(vol), Camera::orbit(world_bounds(file), op, 64, 64));
    const Vec3f eye{float(cam.eye().x / vol.spacing.x), float(cam.eye().y / vol.spacing.y),
                    float(cam.eye().z / vol.spacing.z)};
    const Vec3f eye_file = to_file_index(eye, order, d);

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
        j["spacing"] = {file.spacing.x, file.spacing.y, file.spacing.z};
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
                     {"eye_index", {eye_file.x, eye_file.y, eye_file.z}}};
        j["box_coordinates"] =
            "voxel index of the file: a box spans voxels lo..hi (cells [lo, hi)); world: their "
            "bounding box in patient RAS mm";
        j["ras_order"] = to_string(order);
        nlohmann::json grown = nlohmann::json::array();
        for (const BoxInfo& b : src->grown()) {
            nlohmann::json e = box_json(b.box, file, order);
            e["type"] = to_string(b.type);
            grown.push_back(e);
        }
        j["grown_boxes"] = grown;
        // Every final leaf, front to back for the view; "empty" ones are skipped by the source.
        std::vector<int32_t> front_to_back;
        src->tree().order(eye, front_to_back);
        nlohmann::json list = nlohmann::json::array();
        for (int32_t id : front_to_back) {
            nlohmann::json e = box_json(src->tree().boxes()[size_t(id)].box, file, order);
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
        const Image img = figure2(vol, *src, slice, a.size);
        write_png(a.out, img);
        const int axis = order.axis[2], layer = order.flip[2] ? layers - 1 - slice : slice;
        std::printf(
            "wrote %s (%dx%d, axial slice %d from inferior = index %c %d, seen from above, "
            "patient's right to the right: grown boxes left, BSP leaves right; red uniform, blue "
            "gradient, green other; tinted violet: empty under the TF)\n",
            a.out.c_str(), img.width, img.height, slice, "xyz"[axis], layer);
    }
}

}  // namespace lacuna::cli
