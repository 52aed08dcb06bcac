// `lacuna render`: one frame of a volume to a PNG, with timing and sample statistics.
#include <cstdio>

#include "cli_common.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "core/parallel.h"

namespace lacuna::cli {

namespace {

// The default real dataset: the mricron ch2better brain, 301x370x316 at 0.5 mm (Debian package
// mricron-data), seen obliquely from the front left.
constexpr const char* kDemoVolume = "/usr/share/mricron/templates/ch2better.nii.gz";
constexpr const char* kDemoTf = "mr-brain";
constexpr float kDemoAzimuth = 210.f, kDemoElevation = 30.f;

struct RenderArgs {
    VolumeArgs volume;
    bool demo = false;
    std::string tf;
    std::string accel = "none";
    std::string out;
    std::string heatmap;
    int size = 1024;
    int width = 0, height = 0;
    float azimuth = 30.f, elevation = 15.f, zoom = 1.f, fov = 30.f;
    bool ortho = false;
    bool azimuth_given = false, elevation_given = false;
    float step = 0.5f, ert = 0.99f;
    int threads = 0;
    int leaf = 8, bits = 64, initial_level = -1;
    bool top_down = false;
    std::string background = "0,0,0";
};

Vec3f parse_rgb(const std::string& s) {
    Vec3f c{};
    if (std::sscanf(s.c_str(), "%f,%f,%f", &c.x, &c.y, &c.z) != 3 || c.x < 0 || c.x > 1 ||
        c.y < 0 || c.y > 1 || c.z < 0 || c.z > 1)
        throw Error("--background", "colour", "expected R,G,B in [0,1], got '" + s + "'");
    return c;
}

void run(RenderArgs& a) {
    if (a.demo) {
        if (a.volume.path.empty()) a.volume.path = kDemoVolume;
        if (a.tf.empty()) a.tf = kDemoTf;
        if (a.out.empty()) a.out = "demo.png";
        if (!a.azimuth_given) a.azimuth = kDemoAzimuth;
        if (!a.elevation_given) a.elevation = kDemoElevation;
    }
    if (a.volume.path.empty()) throw Error("render", "volume", "expected a volume file (or --demo)");
    if (a.tf.empty()) throw Error("render", "--tf", "expected a preset name or a .json file");
    if (a.out.empty()) throw Error("render", "--out", "expected an output .png file");
    // Everything that can be checked before the slow work is checked first.
    const AccelKind accel_kind = parse_accel(a.accel);
    check_output_path(a.out, ".png");
    if (!a.heatmap.empty()) check_output_path(a.heatmap, ".png");
    const TransferFunction tf = resolve_transfer_function(a.tf);
    const int w = a.width > 0 ? a.width : a.size, h = a.height > 0 ? a.height : a.size;
    if (w < 1 || h < 1 || w > 16384 || h > 16384)
        throw Error("--size", "image size", "expected 1..16384 pixels per side");
    if (!(a.step > 0.f && a.step <= 64.f)) throw Error("--step", "step", "expected 0 < step <= 64");
    if (!(a.ert > 0.f && a.ert <= 1.f)) throw Error("--ert", "threshold", "expected 0 < ert <= 1");
    RenderOptions ro;
    ro.step = a.step;
    ro.ert = a.ert >= 1.f ? 2.f : a.ert;  // 1 means off: opacity never reaches 2
    ro.threads = a.threads;
    ro.background = parse_rgb(a.background);
    ro.count_samples = !a.heatmap.empty();

    Volume vol = load_volume(a.volume);
    const TransferLut lut = discretise(tf, vol.vis_range());
    AccelOptions ao;
    ao.leaf_cells = a.leaf;
    ao.bitfield_bits = a.bits;
    ao.initial_level = a.initial_level;
    ao.bidirectional = !a.top_down;
    ao.threads = a.threads;
    Progress build_progress("building " + a.accel);
    std::unique_ptr<Accel> accel = make_accel(accel_kind, vol, ao);
    accel->set_transfer_function(lut);
    build_progress.done();
    RayMarcher marcher(vol);
    marcher.set_transfer_function(lut);
    marcher.set_accel(accel.get());
    OrbitParams op;
    op.azimuth_deg = a.azimuth;
    op.elevation_deg = a.elevation;
    op.zoom = a.zoom;
    op.fov_y_deg = a.fov;
    op.projection = a.ortho ? Projection::Orthographic : Projection::Perspective;
    const Camera cam = Camera::orbit(marcher.bounds(), op, w, h);
    RenderResult r = marcher.render(cam, ro);
    write_png(a.out, r.image);
    if (!a.heatmap.empty()) write_png(a.heatmap, heatmap(r.sample_counts, w, h));
    std::printf("%s: %dx%d %s, tf %s, accel %s, %d threads\n", a.volume.path.c_str(), w, h,
                a.ortho ? "orthographic" : "perspective", tf.name.c_str(), a.accel.c_str(),
                resolve_threads(a.threads));
    if (accel_kind != AccelKind::None) {
        const AccelStats& st = accel->stats();
        std::printf("accel %s: build %.1f ms, TF update %.3f ms, %zu nodes, %.2f MiB\n",
                    a.accel.c_str(), st.build_seconds * 1e3, st.tf_update_seconds * 1e3, st.nodes,
                    double(st.bytes) / (1 << 20));
    }
    std::printf("render time %.1f ms, %.1f samples/ray, %.1f Msamples/s (%.1f per thread)\n",
                r.stats.seconds * 1e3, r.stats.samples_per_ray(), r.stats.msamples_per_second(),
                r.stats.msamples_per_second() / resolve_threads(a.threads));
    std::printf("wrote %s\n", a.out.c_str());
}

}  // namespace

void register_render(CLI::App& app) {
    auto a = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand("render", "Render a volume to a PNG");
    add_volume_args(*cmd, a->volume, false);
    cmd->add_flag("--demo", a->demo, "Render the default real dataset (mricron ch2better brain, mr-brain)");
    cmd->add_option("--tf", a->tf, "Transfer function: a preset name or a .json file");
    std::string accels;
    for (const auto& n : accel_names()) accels += (accels.empty() ? "" : ", ") + n;
    cmd->add_option("--accel", a->accel, "Empty-space skipping structure: " + accels)
        ->capture_default_str();
    cmd->add_option("--leaf", a->leaf, "Octree leaf edge in cells (2..64, power of two)")
        ->capture_default_str();
    cmd->add_option("--bits", a->bits, "Bitfield width (8, 16, 32, 64, 128)")->capture_default_str();
    cmd->add_option("--initial-level", a->initial_level,
                    "Octree level traversal starts at (-1 = root)")
        ->capture_default_str();
    cmd->add_flag("--top-down", a->top_down, "Octree traversal restarts at the initial level");
    cmd->add_option("--out,-o", a->out, "Output PNG");
    cmd->add_option("--heatmap", a->heatmap, "Also write a per-pixel sample-count heat map PNG");
    cmd->add_option("--size", a->size, "Image width and height in pixels")->capture_default_str();
    cmd->add_option("--width", a->width, "Image width (overrides --size)");
    cmd->add_option("--height", a->height, "Image height (overrides --size)");
    cmd->add_option("--azimuth", a->azimuth, "Orbit azimuth in degrees")->capture_default_str();
    cmd->add_option("--elevation", a->elevation, "Orbit elevation in degrees")->capture_default_str();
    cmd->add_option("--zoom", a->zoom, "Zoom factor (>1 is closer)")->capture_default_str();
    cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
    cmd->add_flag("--ortho", a->ortho, "Orthographic projection");
    cmd->add_option("--step", a->step, "Sample distance in units of the smallest voxel spacing")
        ->capture_default_str();
    cmd->add_option("--ert", a->ert, "Early ray termination opacity (1 turns it off)")
        ->capture_default_str();
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
    cmd->add_option("--background", a->background, "Background colour R,G,B in [0,1]")
        ->capture_default_str();
    cmd->callback([a, cmd] {
        a->azimuth_given = cmd->count("--azimuth") > 0;
        a->elevation_given = cmd->count("--elevation") > 0;
        run(*a);
    });
}

}  // namespace lacuna::cli
