// `lacuna partition`: the empty-space partition of a volume as boxes — a JSON list and a picture
// of the volume with the box outlines over it (the kd-tree paper's Figures 1, 4 and 5).
//
//   lacuna partition VOLUME --tf PRESET|FILE --method kdtree [--max-boxes M] [--threshold V]
//                    [--json boxes.json] [--out overlay.png]
//
// Classification is by the TF (a cell is non-empty when the TF can make a sample in it visible),
// or with --threshold V by value as in the paper (a cell is non-empty when its largest corner is
// >= V). The picture is always rendered with the TF, exactly (--accel kdtree built from the TF).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>

#include "accel/kdtree_partition.h"
#include "cli_common.h"
#include "core/parallel.h"
#include "io/io_util.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/image.h"
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"
#include "partition_boxes.h"
#include "partition_frame.h"

namespace lacuna::cli {

namespace {

struct PartitionArgs {
    VolumeArgs volume;
    std::string tf;
    std::string method = "kdtree";
    int max_boxes = 0;
    std::optional<float> threshold;
    int delta = 0;
    float min_volume = 0.1f, min_gain = 0.05f;
    int max_depth = 10;
    std::string json, out;
    int size = 512;
    float azimuth = 30.f, elevation = 20.f;
    std::string view;  // --view: a named anatomical view (sets azimuth and elevation)
    int threads = 0;
    int repeat = 1;
    // --method boxes (growing-boxes paper): typed options, the picture's slice, merging.
    BoxesOptions boxes;
    bool no_merge = false;
    int slice = -1;
};

// ---- the overlay: box edges projected through the camera -----------------------------------

// Pixel coordinates of world points for a Camera, derived from generate() itself (so the lines
// sit exactly where the rays go): the rays through the image centre and one pixel right/down
// give the image plane's per-pixel vectors.
class Projector {
  public:
    explicit Projector(const Camera& cam) {
        m_cx = 0.5f * float(cam.width()) - 0.5f;  // pixel coordinate of the optical axis
        m_cy = 0.5f * float(cam.height()) - 0.5f;
        const Ray c = cam.generate(m_cx, m_cy), rx = cam.generate(m_cx + 1, m_cy),
                  ry = cam.generate(m_cx, m_cy + 1);
        m_fwd = cam.forward();
        m_ortho = cam.projection() == Projection::Orthographic;
        if (m_ortho) {
            m_origin = c.origin;
            m_ex = rx.origin - c.origin;
            m_ey = ry.origin - c.origin;
        } else {
            m_origin = cam.eye();
            m_dc = c.dir / dot(c.dir, m_fwd);
            m_ex = rx.dir / dot(rx.dir, m_fwd) - m_dc;
            m_ey = ry.dir / dot(ry.dir, m_fwd) - m_dc;
        }
    }
    // Distance in front of the camera (perspective: along the view axis).
    float depth(Vec3f p) const { return dot(p - m_origin, m_fwd); }
    // Pixel position of p (p must have depth > 0 for perspective).
    void project(Vec3f p, float& px, float& py) const {
        Vec3f q = p - m_origin;
        if (!m_ortho) q = q / dot(q, m_fwd) - m_dc;
        px = m_cx + dot(q, m_ex) / dot(m_ex, m_ex);
        py = m_cy + dot(q, m_ey) / dot(m_ey, m_ey);
    }
    bool orthographic() const { return m_ortho; }

  private:
    float m_cx = 0, m_cy = 0;
    bool m_ortho = false;
    Vec3f m_origin{}, m_fwd{}, m_dc{}, m_ex{}, m_ey{};
};

struct Rgb {
    uint8_t r, g, b;
};

// Blends a `w` x `w` dot of colour c at (x, y).
void plot(Image& img, int x, int y, int w, Rgb c) {
    for (int dy = 0; dy < w; ++dy)
        for (int dx = 0; dx < w; ++dx) {
            const int X = x + dx, Y = y + dy;
            if (X < 0 || Y < 0 || X >= img.width || Y >= img.height) continue;
            uint8_t* p = img.pixel(X, Y);
            p[0] = uint8_t((int(p[0]) + 7 * int(c.r)) / 8);
            p[1] = uint8_t((int(p[1]) + 7 * int(c.g)) / 8);
            p[2] = uint8_t((int(p[2]) + 7 * int(c.b)) / 8);
        }
}

// A DDA line between pixel positions, clipped to a margin around the image.
void draw_line(Image& img, float x0, float y0, float x1, float y1, int w, Rgb c) {
    const float lim = 4.f * float(std::max(img.width, img.height));
    if (std::abs(x0) > lim || std::abs(y0) > lim || std::abs(x1) > lim || std::abs(y1) > lim)
        return;
    const int steps = std::max(1, int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))));
    for (int s = 0; s <= steps; ++s) {
        const float t = float(s) / float(steps);
        plot(img, int(std::lround(x0 + t * (x1 - x0) - 0.5f * float(w - 1))),
             int(std::lround(y0 + t * (y1 - y0) - 0.5f * float(w - 1))), w, c);
    }
}

// The 12 edges of a cell box, in world space (index * spacing), clipped to the camera's front.
void draw_box(Image& img, const Projector& proj, const CellBox& b, Vec3d spacing, int w, Rgb c) {
    auto corner = [&](int m) {
        return Vec3f{float(double(m & 1 ? b.hi[0] : b.lo[0]) * spacing.x),
                     float(double(m & 2 ? b.hi[1] : b.lo[1]) * spacing.y),
                     float(double(m & 4 ? b.hi[2] : b.lo[2]) * spacing.z)};
    };
    for (int m = 0; m < 8; ++m)
        for (int a = 0; a < 3; ++a) {
            const int n = m | (1 << a);
            if (n == m) continue;
            Vec3f p = corner(m), q = corner(n);
            if (!proj.orthographic()) {
                // Keep the part in front of a near plane.
                const float near = 1e-3f, dp = proj.depth(p), dq = proj.depth(q);
                if (dp < near && dq < near) continue;
                if (dp < near) p = p + (q - p) * ((near - dp) / (dq - dp));
                if (dq < near) q = q + (p - q) * ((near - dq) / (dp - dq));
            }
            float x0, y0, x1, y1;
            proj.project(p, x0, y0);
            proj.project(q, x1, y1);
            draw_line(img, x0, y0, x1, y1, w, c);
        }
}

constexpr Rgb kPalette[] = {{255, 64, 64},  {64, 220, 64},  {80, 140, 255}, {255, 220, 40},
                            {255, 80, 255}, {40, 230, 230}, {255, 150, 40}, {180, 120, 255}};

// ---- JSON ------------------------------------------------------------------------------------

// A box of the RAS-order copy in the file's voxel index (cells [lo, hi) are voxels lo..hi), with
// its world (RAS mm) bounding box.
double ms(double s) {
    return std::round(s * 1e6) / 1e3;
}
// Floats as the user typed them (0.05, not 0.05000000074505806).
double round6(float x) {
    return std::round(double(x) * 1e6) / 1e6;
}

void run(const PartitionArgs& a) {
    if (a.method == "boxes") {
        if (a.tf.empty())
            throw Error("partition", "--tf", "expected a preset name or a .json file");
        if (!a.json.empty()) check_output_path(a.json, ".json");
        if (!a.out.empty()) check_output_path(a.out, ".png");
        if (a.size < 16 || a.size > 8192)
            throw Error("--size", "image size", "expected 16..8192 pixels");
        PartitionBoxesArgs b;
        b.volume_path = a.volume.path;
        b.tf = a.tf;
        b.json = a.json;
        b.out = a.out;
        b.options = a.boxes;
        b.options.merge = !a.no_merge;
        b.options.threads = a.threads;
        b.slice = a.slice;
        b.size = a.size;
        b.azimuth = a.azimuth;
        b.elevation = a.elevation;
        b.repeat = a.repeat;
        validate(b.options);  // before loading anything
        if (b.repeat < 1 || b.repeat > 1000) throw Error("--repeat", "repeat", "expected 1..1000");
        resolve_transfer_function(b.tf);
        run_partition_boxes(b, load_volume(a.volume));
        return;
    }
    if (a.method != "kdtree")
        throw Error("--method", "method",
                    "unknown '" + a.method + "'; expected one of: kdtree, boxes");
    if (a.tf.empty()) throw Error("partition", "--tf", "expected a preset name or a .json file");
    if (!a.json.empty()) check_output_path(a.json, ".json");
    if (!a.out.empty()) check_output_path(a.out, ".png");
    if (a.size < 16 || a.size > 8192)
        throw Error("--size", "image size", "expected 16..8192 pixels");
    if (a.threshold && !std::isfinite(*a.threshold))
        throw Error("--threshold", "threshold", "expected a finite value");
    AccelOptions ao;
    ao.kd_max_boxes = a.max_boxes;
    ao.kd_delta = a.delta;
    ao.kd_min_volume = a.min_volume;
    ao.kd_min_gain = a.min_gain;
    ao.kd_max_depth = a.max_depth;
    ao.threads = a.threads;
    const KdSettings settings = kd_settings(ao);  // validates before loading anything

    const TransferFunction tf = resolve_transfer_function(a.tf);
    const Volume vol = load_volume(a.volume);
    const TransferLut lut = discretise(tf, vol.vis_range());
    // The partition is built on the voxels in RAS order (partition_frame.h), so the same anatomy
    // in any voxel order gives the same boxes; the picture under them is rendered from the file.
    const RasOrder order = ras_order(vol);
    const Volume ras = order.identity() ? vol : reorder(vol, order);

    if (a.repeat < 1 || a.repeat > 1000) throw Error("--repeat", "repeat", "expected 1..1000");
    // Steps 1-4, `repeat` times (the table is reused, as on a TF change); the median of each
    // step is reported, which is what a loaded machine needs.
    KdPartition part;
    std::vector<KdTimings> runs;
    for (int r = 0; r < a.repeat; ++r) {
        if (a.threshold)
            part.build_from_threshold(ras, *a.threshold, settings);
        else
            part.build_from_tf(ras, lut, settings);
        runs.push_back(part.timings());
    }
    auto median = [&](double KdTimings::*field) {
        std::vector<double> v;
        for (const KdTimings& t : runs) v.push_back(t.*field);
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    KdTimings t;
    t.classify = median(&KdTimings::classify);
    t.table = median(&KdTimings::table);
    t.tree = median(&KdTimings::tree);
    t.list = median(&KdTimings::list);

    // The default view: the overlay's camera; boxes front to back for its eye.
    OrbitParams op;
    op.azimuth_deg = a.azimuth;
    op.elevation_deg = a.elevation;
    const Camera cam = Camera::orbit(world_bounds(vol), op, a.size, a.size);  // world (RAS)
    // The boxes live in the RAS-order copy's volume frame (index * spacing): project and order
    // them there.
    const Camera vcam = to_volume_frame(volume_frame(ras), cam);
    const Vec3f eye_index{float(vcam.eye().x / ras.spacing.x), float(vcam.eye().y / ras.spacing.y),
                          float(vcam.eye().z / ras.spacing.z)};
    const std::vector<CellBox> boxes = part.boxes_in_visibility_order(eye_index);
    const Vec3f eye_file = to_file_index(eye_index, order, vol.dims());

    const Vec3i d = vol.dims();
    const int leaves = part.nodes().empty() ? 0 : part.nodes()[0].leaves;
    std::printf("%s: %dx%dx%d, %s classification%s, kd-tree %zu nodes, %d leaves, depth %d\n",
                a.volume.path.c_str(), d.x, d.y, d.z, a.threshold ? "threshold" : "TF",
                a.threshold ? (" >= " + std::to_string(*a.threshold)).c_str()
                            : (" (" + tf.name + ")").c_str(),
                part.nodes().size(), leaves, part.depth());
    std::printf("settings: M %d, delta %d, min volume %g, min gain %g, max depth %d, %d threads\n",
                settings.max_boxes, part.delta(), double(settings.min_volume),
                double(settings.min_gain), settings.max_depth, resolve_threads(a.threads));
    std::printf(
        "steps%s: classify %.1f ms, table %.1f ms, tree %.1f ms, list %.3f ms "
        "(preprocessing 1-3: %.1f ms)\n",
        a.repeat > 1 ? (" (median of " + std::to_string(a.repeat) + ")").c_str() : "",
        t.classify * 1e3, t.table * 1e3, t.tree * 1e3, t.list * 1e3, t.preprocess() * 1e3);
    std::printf(
        "%zu boxes, %.1f%% of the volume removed (%.1f%% of the empty space); "
        "%.1f%% of the cells non-empty\n",
        boxes.size(), 100 * part.removed_fraction(), 100 * part.removed_empty_fraction(),
        100.0 * double(part.non_empty_cells()) / double(part.total_cells()));

    if (!a.json.empty()) {
        nlohmann::json j;
        j["volume"] = a.volume.path;
        j["dims"] = {d.x, d.y, d.z};
        j["cells"] = {d.x - 1, d.y - 1, d.z - 1};
        j["spacing"] = {vol.spacing.x, vol.spacing.y, vol.spacing.z};
        j["method"] = a.method;
        j["classification"] = a.threshold ? "threshold" : "tf";
        if (a.threshold) j["threshold"] = round6(*a.threshold);
        j["tf"] = tf.name;
        j["settings"] = {
            {"max_boxes", settings.max_boxes},           {"delta", part.delta()},
            {"min_volume", round6(settings.min_volume)}, {"min_gain", round6(settings.min_gain)},
            {"max_depth", settings.max_depth},           {"threads", resolve_threads(a.threads)},
            {"wide_counts", part.wide_counts()}};
        j["timings_ms"] = {{"classify", ms(t.classify)},
                           {"table", ms(t.table)},
                           {"tree", ms(t.tree)},
                           {"list", ms(t.list)},
                           {"preprocess", ms(t.preprocess())},
                           {"repeat", a.repeat}};
        j["tree"] = {{"nodes", part.nodes().size()}, {"leaves", leaves}, {"depth", part.depth()}};
        j["total_cells"] = part.total_cells();
        j["non_empty_cells"] = part.non_empty_cells();
        j["listed_cells"] = part.listed_cells();
        j["volume_removed_percent"] = 100 * part.removed_fraction();
        j["empty_space_removed_percent"] = 100 * part.removed_empty_fraction();
        j["view"] = {{"azimuth", a.azimuth},
                     {"elevation", a.elevation},
                     {"eye_index", {eye_file.x, eye_file.y, eye_file.z}}};
        j["box_coordinates"] =
            "voxel index of the file: a box spans voxels lo..hi (cells [lo, hi)); world: their "
            "bounding box in patient RAS mm";
        j["ras_order"] = to_string(order);
        nlohmann::json list = nlohmann::json::array();
        for (const CellBox& b : boxes) {
            uint64_t ne = 0;
            for (const KdNode& n : part.nodes())
                if (std::memcmp(&n.box, &b, sizeof b) == 0) ne = n.non_empty;
            nlohmann::json e = box_json(b, vol, order);
            e["non_empty_cells"] = ne;
            list.push_back(e);
        }
        j["boxes"] = list;
        io::write_text_atomic(a.json, j.dump(2) + "\n");
        std::printf("wrote %s\n", a.json.c_str());
    }

    if (!a.out.empty()) {
        // The picture is rendered with the TF (exactly, skipping with the TF's own kd-tree),
        // through a Session as every front end's frame (it shares the voxels): the view is the
        // overlay's camera, Camera::orbit of the volume's world bounds.
        Session session(vol, a.threads);
        session.set_transfer_function(tf);
        FrameSpec frame;
        frame.structure = structure_of(AccelKind::KdTree, ao);
        frame.camera.orbit = op;
        frame.width = frame.height = a.size;
        FrameResult r = session.render(frame);
        const Projector proj(vcam);
        const int w = a.size >= 384 ? 2 : 1;
        for (size_t i = 0; i < boxes.size(); ++i)
            draw_box(r.image, proj, boxes[i], ras.spacing, w, kPalette[i % std::size(kPalette)]);
        write_png(a.out, r.image);
        std::printf("wrote %s (%dx%d, render %.1f ms)\n", a.out.c_str(), a.size, a.size,
                    r.stats.seconds * 1e3);
    }
}

}  // namespace

void register_partition(CLI::App& app) {
    auto a = std::make_shared<PartitionArgs>();
    auto* cmd = app.add_subcommand(
        "partition", "Empty-space partition of a volume as boxes: JSON and an overlay picture");
    add_volume_args(*cmd, a->volume);
    cmd->add_option("--tf", a->tf, "Transfer function: a preset name or a .json file")->required();
    cmd->add_option("--method", a->method, "Partition method: kdtree or boxes")
        ->capture_default_str();
    cmd->add_option("--max-boxes", a->max_boxes, "M: at most this many boxes (0 = every leaf)")
        ->capture_default_str();
    cmd->add_option("--threshold", a->threshold,
                    "Classify by value (non-empty when a cell's largest corner >= V) instead of "
                    "by the TF; the picture still uses the TF");
    cmd->add_option("--delta", a->delta, "Candidate plane spacing in cells (0 = longest axis / 64)")
        ->capture_default_str();
    cmd->add_option("--min-volume", a->min_volume,
                    "Halting: nodes below this fraction of the volume are leaves")
        ->capture_default_str();
    cmd->add_option("--min-gain", a->min_gain,
                    "Halting: a split must remove this fraction of its node")
        ->capture_default_str();
    cmd->add_option("--max-depth", a->max_depth, "Halting: deepest split level")
        ->capture_default_str();
    cmd->add_option("--json", a->json, "Write the boxes (voxel index coordinates) as JSON");
    cmd->add_option("--out,-o", a->out, "Write the volume with the box outlines as a PNG");
    cmd->add_option("--size", a->size, "Overlay image width and height")->capture_default_str();
    cmd->add_option("--azimuth", a->azimuth, "Overlay orbit azimuth in degrees")
        ->capture_default_str();
    cmd->add_option("--elevation", a->elevation, "Overlay orbit elevation in degrees")
        ->capture_default_str();
    cmd->add_option("--view", a->view, kViewHelp);
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->add_option("--repeat", a->repeat,
                    "Run steps 1-4 this many times; report median step times")
        ->capture_default_str();
    // --method boxes (docs/growing-boxes.md).
    cmd->add_option("--spread", a->boxes.spread,
                    "boxes: uniform box value spread in 256ths of the full scale")
        ->capture_default_str();
    cmd->add_option("--min-box", a->boxes.min_uniform, "boxes: smallest uniform box edge, cells")
        ->capture_default_str();
    cmd->add_option("--gradient", a->boxes.gradient,
                    "boxes: gradient cell above this |grad| (full scale per voxel)")
        ->capture_default_str();
    cmd->add_option("--gradient-waste", a->boxes.gradient_waste,
                    "boxes: most non-gradient share of a gradient box")
        ->capture_default_str();
    cmd->add_option("--other-cost", a->boxes.other_cost,
                    "boxes: other box cost bound (volume x spread / full scale, cells)")
        ->capture_default_str();
    cmd->add_option("--thin", a->boxes.thin, "boxes: merge rule 3, thinner than this many cells")
        ->capture_default_str();
    cmd->add_flag("--no-merge", a->no_merge, "boxes: skip the BSP tree's bottom-up merging");
    cmd->add_option("--slice", a->slice, "boxes: z cell layer of the picture (-1 = middle)")
        ->capture_default_str();
    cmd->callback([a, cmd] {
        if (!a->view.empty()) {
            if (cmd->count("--azimuth") || cmd->count("--elevation"))
                throw Error("--view", "view",
                            "sets the azimuth and elevation; drop --azimuth/--elevation");
            parse_view(a->view, a->azimuth, a->elevation);
        }
        Progress summary("partition", 0, "");
        run(*a);
        std::fflush(stdout);
        summary.done();
    });
}

}  // namespace lacuna::cli
