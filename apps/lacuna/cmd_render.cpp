// `lacuna render`: one frame of a volume to a PNG, with timing and sample statistics; with
// --orbit N, N frames around the volume; or, with --tf-animate, a sequence while the TF moves
// between two TFs (bitfield paper, Section 4.5), reporting per structure the time from a TF change
// to ready-to-render. Sequences are numbered PNGs (frame_path) and, with --movie, an MP4 (movie.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli_common.h"
#include "core/parallel.h"
#include "feature_args.h"
#include "frame_flags.h"
#include "io/io_util.h"
#include "lacuna/accel.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"
#include "movie.h"
#include "render_mpi.h"
#include "render_slice.h"
#include "segments_cli.h"
#include "session/session_file.h"

namespace lacuna::cli {

namespace {

// The default real dataset: the mricron ch2better brain, 301x370x316 at 0.5 mm (Debian package
// mricron-data), seen obliquely from the front left.
constexpr const char* kDemoVolume = "/usr/share/mricron/templates/ch2better.nii.gz";
constexpr const char* kDemoTf = "mr-brain";
constexpr float kDemoAzimuth = 30.f, kDemoElevation = 30.f;  // the face, from the front-left

struct RenderArgs {
    VolumeArgs volume;
    bool demo = false;
    std::string tf;
    std::vector<std::string> tf_animate;
    int frames = 36;
    int orbit = 0;      // --orbit N: N frames around the orbit (0: one frame)
    std::string movie;  // --movie out.mp4: the sequence as an H.264 MP4 too
    int fps = 24;
    std::string session;       // --session FILE: the frame a session file describes
    std::string save_session;  // --save-session FILE: write the command line's frame as one
    // The TFs a session file holds (instead of resolving --tf / --tf-back).
    std::optional<TransferFunction> tf_value, tf_back_value;
    int repeat = 1;  // --repeat: the same frame this many times (warm frames, median reported)
    bool no_refine = false;      // --no-refine: frames without the structure's finer per-TF level
    std::string accel = "auto";  // default_accel() for the ray marcher (docs/cli.md)
    std::string out;
    std::string heatmap;
    int size = 1024;
    int width = 0, height = 0;
    float azimuth = 30.f, elevation = 15.f, zoom = 1.f, fov = 30.f;
    bool ortho = false;
    bool azimuth_given = false, elevation_given = false;
    std::string view;  // --view: a named anatomical view
    float step = 0.5f, ert = 0.99f;
    std::string interpolation = "trilinear";
    int threads = 0;
    int leaf = 8, bits = 64, initial_level = -1;
    bool top_down = false;
    std::string background = "0,0,0";
    FeatureArgs features;  // shading, lights, clipping, blend modes (feature_args.h)
    SegmentArgs segments;
    SliceCliArgs slice;  // --renderer, --occlusion* (render_slice.h)
    MpiCliArgs mpi;      // --balance, --composite, --rank-times (under mpirun; render_mpi.h)
};

Vec3f parse_rgb(const std::string& s) {
    Vec3f c{};
    if (std::sscanf(s.c_str(), "%f,%f,%f", &c.x, &c.y, &c.z) != 3 || c.x < 0 || c.x > 1 ||
        c.y < 0 || c.y > 1 || c.z < 0 || c.z > 1)
        throw Error("--background", "colour", "expected R,G,B in [0,1], got '" + s + "'");
    return c;
}

// "--accel all" or a comma-separated list.
std::vector<AccelKind> parse_accels(const std::string& s) {
    if (s == "all") return all_accel_kinds();
    std::vector<AccelKind> out;
    size_t pos = 0;
    for (;;) {
        const size_t c = s.find(',', pos);
        out.push_back(
            parse_accel(s.substr(pos, c == std::string::npos ? std::string::npos : c - pos)));
        if (c == std::string::npos) break;
        pos = c + 1;
    }
    return out;
}

// Frame i of a sequence of n (--orbit, --tf-animate) written beside `out`: head.png ->
// head_0007.png. One rule for both: the number has four digits, or as many as n - 1 has when that
// is more, so the names sort in frame order and ffmpeg's "%04d" pattern reads them.
std::string frame_path(const std::string& out, int i, int n) {
    namespace fs = std::filesystem;
    fs::path p(out);
    const int digits = std::max<int>(4, int(std::to_string(std::max(n - 1, 0)).size()));
    char num[24];
    std::snprintf(num, sizeof num, "_%0*d", digits, i);
    return (p.parent_path() / (p.stem().string() + num + p.extension().string())).string();
}

// The azimuth of orbit frame i of n: the start plus i/n of a turn, in float as the single-frame
// --azimuth is, so frame i is byte for byte `render --azimuth <that value>`.
float orbit_azimuth(float start, int i, int n) {
    return start + 360.f * float(i) / float(n);
}

// The frame the flags describe (the strings become a FrameSpec here; its ranges are checked by
// lacuna::validate, whose fields frame_flags.cpp translates back to flags).
struct Setup {
    FrameSpec spec;
    AccelOptions ao;  // the octree and bitfield flags, for structure_of()
};

// The structure `name` names for the renderer of `spec` (lacuna::parse_structure: "auto" is the
// renderer's default, the segment renderer's "bitfield" the label octree).
Structure structure_from(const std::string& name, const RenderArgs& a, const Setup& s) {
    return parse_structure(name, s.spec.renderer, s.ao,
                           structure::GrowingBoxes{a.slice.coalesce, a.slice.coalesce_edge});
}

// The outputs and sequence flags, for frames from flags and from a session file alike.
void check_outputs(const RenderArgs& a) {
    const bool sequence = a.orbit != 0 || !a.tf_animate.empty();
    if (a.orbit < 0 || a.orbit > 100000) throw Error("--orbit", "frames", "expected 1..100000");
    if (a.orbit && !a.tf_animate.empty())
        throw Error("--orbit", "frames", "not with --tf-animate (one sequence at a time)");
    if (a.orbit && a.repeat != 1) throw Error("--repeat", "frames", "not with --orbit");
    if (a.orbit && !a.heatmap.empty()) throw Error("--heatmap", "frames", "not with --orbit");
    if (a.orbit && (a.segments.active() || a.slice.renderer == "slice"))
        throw Error("--orbit", "renderer",
                    "the ray marcher only (not --renderer slice or segments)");
    if (!a.movie.empty()) {
        if (!sequence) throw Error("--movie", "frames", "needs --orbit N or --tf-animate A B");
        if (a.accel == "all" || a.accel.find(',') != std::string::npos)
            throw Error("--movie", "structure", "one structure only (not a list in --accel)");
        check_output_path(a.movie, ".mp4");
        if (a.fps < 1 || a.fps > 240) throw Error("--fps", "frames", "expected 1..240");
        require_ffmpeg();  // before any work
    }
    if (!a.save_session.empty()) {
        if (!a.tf_animate.empty())
            throw Error("--save-session", "frames", "a single frame or --orbit, not --tf-animate");
        check_output_path(a.save_session, ".json");
    }
    if (a.out.empty() && a.movie.empty())
        throw Error("render", "--out", "expected an output .png file");
    if (!a.out.empty()) check_output_path(a.out, ".png");
}

// The front and back TFs of the frame: a session file's, else --tf / --tf-back resolved.
TransferFunction front_tf(const RenderArgs& a) {
    return a.tf_value ? *a.tf_value : resolve_transfer_function(a.tf);
}
std::optional<TransferFunction> back_tf(const RenderArgs& a, const FrameSpec& spec) {
    if (!spec.two_tfs) return std::nullopt;
    return a.tf_back_value ? *a.tf_back_value : resolve_transfer_function(a.features.tf_back);
}

// --session FILE: the frame, volume and TFs from the file (session/session_file.h); only the
// outputs and how to run come from flags.
Setup from_session(RenderArgs& a) {
    const SessionFile f = load_session_file(a.session);
    const std::string max_memory = a.volume.max_memory;  // how to run, not the frame
    a.volume = VolumeArgs{};
    a.volume.max_memory = max_memory;
    a.volume.path = f.volume.path;
    a.volume.frame = f.volume.frame;
    a.volume.raw_spec = f.volume.raw;
    a.volume.range_value = f.volume.range;
    a.tf_value = f.tf;
    a.tf = f.tf.name.empty() ? "session" : f.tf.name;
    a.tf_back_value = f.tf_back;
    a.accel = structure_name(f.frame.structure);
    a.azimuth = f.frame.camera.orbit.azimuth_deg;
    a.elevation = f.frame.camera.orbit.elevation_deg;
    a.ortho = f.frame.camera.orbit.projection == Projection::Orthographic;
    a.slice.renderer = f.frame.renderer == Renderer::Slicer ? "slice" : "march";
    // The segment renderer: its label volume (mask mode), mode and table from the file.
    a.segments = SegmentArgs{};
    if (f.frame.renderer == Renderer::Segments) {
        a.segments.mode = f.frame.segments.mode == SegmentMode::Labels ? "labels" : "mask";
        a.segments.labels = f.labels.value_or("");
        a.segments.tint = f.frame.segments.tint;
    }
    check_outputs(a);
    Setup s;
    s.spec = f.frame;
    return s;
}

// --save-session: the command line's frame as a session file (written once the frame is).
std::string session_text(const RenderArgs& a, const Setup& s) {
    namespace fs = std::filesystem;
    if (s.spec.renderer == Renderer::Segments)
        throw Error("--save-session", "frame.renderer",
                    "not yet for the segment renderer (its label table is made while "
                    "rendering); the viewer's session button saves one");
    SessionFile f;
    f.volume.path = fs::absolute(a.volume.path).lexically_normal().string();
    f.volume.frame = a.volume.frame;
    f.volume.raw = a.volume.raw_spec ? a.volume.raw_spec : raw_spec_of(a.volume);
    if (a.volume.range_value)
        f.volume.range = a.volume.range_value;
    else if (!a.volume.range.empty())
        f.volume.range = parse_range(a.volume.range);
    f.tf = front_tf(a);
    f.tf_back = back_tf(a, s.spec);
    f.frame = s.spec;
    f.frame.count_samples = false;  // the heat map is an output, not the frame
    return to_json(f, "--save-session");
}

Setup validate(RenderArgs& a) {
    if (!a.session.empty()) return from_session(a);
    if (!a.view.empty()) {
        if (a.azimuth_given || a.elevation_given)
            throw Error("--view", "view",
                        "sets the azimuth and elevation; drop --azimuth/--elevation");
        parse_view(a.view, a.azimuth, a.elevation);
        a.azimuth_given = a.elevation_given = true;
    }
    if (a.demo) {
        if (a.volume.path.empty()) a.volume.path = kDemoVolume;
        if (a.tf.empty()) a.tf = kDemoTf;
        if (a.out.empty()) a.out = "demo.png";
        if (!a.azimuth_given) a.azimuth = kDemoAzimuth;
        if (!a.elevation_given) a.elevation = kDemoElevation;
    }
    if (a.volume.path.empty())
        throw Error("render", "volume", "expected a volume file (or --demo)");
    const bool labels_alone = a.segments.mode == "labels";
    if (a.tf.empty() && a.tf_animate.empty() && !labels_alone)
        throw Error("render", "--tf", "expected a preset name or a .json file");
    check_outputs(a);
    if (!a.heatmap.empty()) check_output_path(a.heatmap, ".png");
    if (a.frames < 2 || a.frames > 100000) throw Error("--frames", "frames", "expected 2..100000");
    if (a.repeat < 1 || a.repeat > 100000) throw Error("--repeat", "frames", "expected 1..100000");
    check_slice_options(a.slice, !a.tf_animate.empty(), !a.heatmap.empty());
    check_mpi_options(a.mpi);
    if (!a.tf_animate.empty() && !a.features.tf_back.empty())
        throw Error("--tf-back", "transfer function", "not supported with --tf-animate");
    if (a.segments.active() && !a.tf_animate.empty())
        throw Error("--tf-animate", "segments", "not available with --labels/--segments");
    if (a.segments.active() && a.slice.renderer == "slice")
        throw Error("--renderer", "segments", "segments are rendered by the ray marcher only");

    Setup s;
    FrameSpec& f = s.spec;
    f.renderer = a.segments.active()           ? Renderer::Segments
                 : a.slice.renderer == "slice" ? Renderer::Slicer
                                               : Renderer::RayMarcher;
    f.width = a.width > 0 ? a.width : a.size;
    f.height = a.height > 0 ? a.height : a.size;
    f.sampling.step = a.step;
    // --ert 1 means off (nullopt); any other value is checked by validate().
    f.sampling.early_termination = a.ert == 1.f ? std::nullopt : std::optional<float>(a.ert);
    f.sampling.interpolation = parse_interpolation(a.interpolation);
    f.background = parse_rgb(a.background);
    f.count_samples = !a.heatmap.empty();
    f.features = parse_features(a.features);
    f.two_tfs = !a.features.tf_back.empty();
    f.camera.orbit.azimuth_deg = a.azimuth;
    f.camera.orbit.elevation_deg = a.elevation;
    f.camera.orbit.zoom = a.zoom;
    f.camera.orbit.fov_y_deg = a.fov;
    f.camera.orbit.projection = a.ortho ? Projection::Orthographic : Projection::Perspective;
    f.slicer.occlusion = a.slice.occlusion;
    f.slicer.occlusion_threshold = a.slice.occlusion_threshold;
    f.slicer.occlusion_map = a.slice.occlusion_map;
    if (a.segments.active()) {
        f.segments.mode =
            parse_segment_mode(a.segments.mode.empty() ? "mask" : a.segments.mode, "--segments");
        f.segments.tint = a.segments.tint;
    }
    s.ao.leaf_cells = a.leaf;
    s.ao.bitfield_bits = a.bits;
    s.ao.initial_level = a.initial_level;
    s.ao.bidirectional = !a.top_down;
    // --tf-animate takes a list of structures (render_animation); the frame carries the first.
    const std::string first = a.accel.substr(0, a.accel.find(','));
    f.structure = first == "all" ? Structure{structure::None{}} : structure_from(first, a, s);
    // The TF's rendering (a Slicer preset's shading and gradient opacity, a MIP preset's blend)
    // sets the features whose flags were not given, where the renderer takes them
    // (apply_tf_rendering; docs/transfer-functions.md). A TF animation takes its first TF's.
    if (f.renderer == Renderer::RayMarcher) {
        if (!a.tf_animate.empty())
            apply_tf_rendering(resolve_transfer_function(a.tf_animate[0]).rendering, f,
                               a.features.given);
        else if (!a.tf.empty()) {
            a.tf_value = resolve_transfer_function(a.tf);
            apply_tf_rendering(a.tf_value->rendering, f, a.features.given);
        }
    }
    validate_flags(f);
    return s;
}

void print_accel(const Structure& st, const AccelStats& stats) {
    const std::optional<AccelKind> k = accel_kind(st);
    if (!k || *k == AccelKind::None) return;
    std::printf("accel %s: build %.1f ms, TF update %.3f ms, refine %.3f ms, %zu nodes, %.2f MiB\n",
                to_string(*k).c_str(), stats.build_seconds * 1e3, stats.tf_update_seconds * 1e3,
                stats.refine_seconds * 1e3, stats.nodes, double(stats.bytes) / (1 << 20));
}

void render_one(const RenderArgs& a, const Setup& s) {
    const FrameSpec& spec = s.spec;
    Progress summary("render", a.repeat, "frame");
    const TransferFunction tf = front_tf(a);
    const std::optional<TransferFunction> back = back_tf(a, spec);
    Session session(load_volume(a.volume), a.threads);
    session.set_transfer_function(tf);
    // Two TFs: the structure skips only where both are transparent (the session gives it
    // their union).
    if (back) session.set_back_transfer_function(back);
    Progress progress("building " + structure_name(spec.structure));
    session.prepare(spec);
    progress.done();
    if (!a.no_refine) session.refine();  // the structure's finer per-TF level, before the frame
    // --repeat N: frame 1 warms caches, pages and threads (as the VTK peer's warm-up render);
    // the reported time is the median of the N - 1 frames after it (every frame gives the same
    // bytes: the renderer is deterministic).
    FrameResult r = session.render(spec);
    summary.step(1);
    const double first_ms = r.stats.seconds * 1e3;
    if (a.repeat > 1) {
        std::vector<RenderStats> warm;
        for (int f = 1; f < a.repeat; ++f) {
            warm.push_back(session.render(spec).stats);
            summary.step(f + 1);
        }
        std::sort(warm.begin(), warm.end(),
                  [](const RenderStats& x, const RenderStats& y) { return x.seconds < y.seconds; });
        r.stats = warm[warm.size() / 2];
    }
    write_png(a.out, r.image);
    if (!a.heatmap.empty()) write_png(a.heatmap, heatmap(r.sample_counts, spec.width, spec.height));
    std::printf("%s: %dx%d %s, tf %s, accel %s, %d threads\n", a.volume.path.c_str(), spec.width,
                spec.height, a.ortho ? "orthographic" : "perspective", tf.name.c_str(),
                a.accel.c_str(), resolve_threads(a.threads));
    if (r.structure) print_accel(spec.structure, *r.structure);
    if (const std::string f = describe(spec.features); !f.empty())
        std::printf("features: %s\n", f.c_str());
    if (r.stats.gradient_volume_bytes)
        std::printf("gradient volume: %.2f MiB, computed in %.1f ms\n",
                    double(r.stats.gradient_volume_bytes) / (1 << 20),
                    r.stats.gradient_volume_seconds * 1e3);
    if (r.stats.light_volume_bytes)
        std::printf("light volume: %.2f MiB, computed in %.1f ms (part of the render time)\n",
                    double(r.stats.light_volume_bytes) / (1 << 20),
                    r.stats.light_volume_seconds * 1e3);
    if (r.stats.shadow_samples)
        std::printf("shadow samples: %.1f per ray\n",
                    double(r.stats.shadow_samples) / double(std::max<uint64_t>(r.stats.rays, 1)));
    if (a.repeat > 1)
        std::printf("%d frames: first %.1f ms, the median of the other %d below\n", a.repeat,
                    first_ms, a.repeat - 1);
    std::printf(
        "render time %.1f ms, %.1f samples/ray, %.1f Msamples/s (%.1f per thread), CPU %.1f ms\n",
        r.stats.seconds * 1e3, r.stats.samples_per_ray(), r.stats.msamples_per_second(),
        r.stats.msamples_per_second() / resolve_threads(a.threads), r.stats.cpu_seconds * 1e3);
    std::printf("wrote %s\n", a.out.c_str());
    std::fflush(stdout);
    summary.done();
}

// --orbit N: N frames of one spec, the azimuth stepping a turn from --azimuth at a fixed
// elevation, through one session (the structure is built once). Each frame goes to its numbered
// PNG and, with --movie, to ffmpeg; the MP4 appears only when every frame is in and ffmpeg
// succeeded.
void render_orbit(const RenderArgs& a, const Setup& s) {
    FrameSpec spec = s.spec;
    const TransferFunction tf = front_tf(a);
    const std::optional<TransferFunction> back = back_tf(a, spec);
    Session session(load_volume(a.volume), a.threads);
    session.set_transfer_function(tf);
    if (back) session.set_back_transfer_function(back);
    Progress building("building " + structure_name(spec.structure));
    session.prepare(spec);
    building.done();
    if (!a.no_refine) session.refine();
    std::optional<MovieWriter> movie;
    if (!a.movie.empty()) movie.emplace(a.movie, spec.width, spec.height, a.fps);
    Progress progress("render", a.orbit, "frame");
    double frame_sum = 0, spr_sum = 0;
    for (int i = 0; i < a.orbit; ++i) {
        spec.camera.orbit.azimuth_deg = orbit_azimuth(a.azimuth, i, a.orbit);
        const FrameResult r = session.render(spec);
        if (!a.out.empty()) write_png(frame_path(a.out, i, a.orbit), r.image);
        if (movie) movie->add(r.image);
        frame_sum += r.stats.seconds;
        spr_sum += r.stats.samples_per_ray();
        progress.step(i + 1);
    }
    if (movie) movie->finish();
    std::printf(
        "%s: orbit of %d frames from azimuth %g at elevation %g, %dx%d, tf %s, accel %s, "
        "%d threads\n",
        a.volume.path.c_str(), a.orbit, a.azimuth, a.elevation, spec.width, spec.height,
        tf.name.c_str(), a.accel.c_str(), resolve_threads(a.threads));
    std::printf("frame time %.1f ms (mean), %.1f samples/ray\n", frame_sum / a.orbit * 1e3,
                spr_sum / a.orbit);
    if (!a.out.empty())
        std::printf("wrote %s .. %s\n", frame_path(a.out, 0, a.orbit).c_str(),
                    frame_path(a.out, a.orbit - 1, a.orbit).c_str());
    if (movie)
        std::printf("wrote %s (%d frames at %d fps)\n", a.movie.c_str(), movie->frames(), a.fps);
    std::fflush(stdout);
    progress.done();
}

// The TF animation: frames with the TF interpolated from A to B. For every structure the TF
// change (LUT + structure update, through the session) is timed separately from the frame.
void render_animation(const RenderArgs& a, const Setup& s) {
    if (a.tf_animate.size() != 2)
        throw Error("--tf-animate", "transfer functions", "expected two: A B");
    const std::vector<AccelKind> kinds = parse_accels(a.accel);
    const TransferFunction tf_a = resolve_transfer_function(a.tf_animate[0]);
    const TransferFunction tf_b = resolve_transfer_function(a.tf_animate[1]);
    Session session(load_volume(a.volume), a.threads);
    const bool write_frames = kinds.size() == 1 && !a.out.empty();
    std::optional<MovieWriter> movie;
    if (!a.movie.empty()) movie.emplace(a.movie, s.spec.width, s.spec.height, a.fps);
    Progress progress("render", int64_t(kinds.size()) * a.frames, "frame");
    int64_t frames_done = 0;
    std::printf("%s: TF animation %s -> %s, %d frames at %dx%d, %d threads\n",
                a.volume.path.c_str(), tf_a.name.c_str(), tf_b.name.c_str(), a.frames, s.spec.width,
                s.spec.height, resolve_threads(a.threads));
    std::printf("%-10s %12s %16s %16s %14s %12s\n", "accel", "build [ms]", "TF change [ms]",
                "TF change max", "frame [ms]", "samples/ray");
    for (AccelKind k : kinds) {
        FrameSpec spec = s.spec;
        spec.structure = structure_of(k, s.ao);
        // One structure at a time (memory), built holding B so that frame 0 (A) is a TF change.
        session.drop_structures();
        session.set_transfer_function(tf_b);
        Progress building("building " + to_string(k));
        const double build_ms = session.prepare(spec).structure->build_seconds * 1e3;
        building.done();
        double tf_sum = 0, tf_max = 0, frame_sum = 0, spr_sum = 0;
        for (int f = 0; f < a.frames; ++f) {
            const float w = float(f) / float(a.frames - 1);
            const auto t0 = std::chrono::steady_clock::now();
            session.set_transfer_function(lerp(tf_a, tf_b, w));
            session.prepare(spec);
            const double tf_change =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const FrameResult r = session.render(spec);
            if (write_frames) write_png(frame_path(a.out, f, a.frames), r.image);
            if (movie) movie->add(r.image);
            tf_sum += tf_change;
            tf_max = std::max(tf_max, tf_change);
            frame_sum += r.stats.seconds;
            spr_sum += r.stats.samples_per_ray();
            progress.step(++frames_done);
        }
        std::printf("%-10s %12.1f %16.3f %16.3f %14.1f %12.1f\n", to_string(k).c_str(), build_ms,
                    tf_sum / a.frames * 1e3, tf_max * 1e3, frame_sum / a.frames * 1e3,
                    spr_sum / a.frames);
    }
    if (movie) movie->finish();
    if (write_frames)
        std::printf("wrote %s .. %s\n", frame_path(a.out, 0, a.frames).c_str(),
                    frame_path(a.out, a.frames - 1, a.frames).c_str());
    if (movie)
        std::printf("wrote %s (%d frames at %d fps)\n", a.movie.c_str(), movie->frames(), a.fps);
    std::fflush(stdout);
    progress.done();
}

void render_frames(RenderArgs& a, const Setup& s) {
    // What `auto` resolved to, for the reports: the segment renderer's fastest exact structure is
    // the label bitfield octree; the slicer slices the whole volume (its structures are the
    // papers' boxes, chosen explicitly); the ray marcher takes default_accel().
    const std::string accel = a.accel != "auto"                       ? a.accel
                              : s.spec.renderer == Renderer::Segments ? "bitfield"
                              : s.spec.renderer == Renderer::Slicer   ? "none"
                                                                      : a.accel;
    if (mpi_render_active() && s.spec.renderer != Renderer::RayMarcher)
        throw Error("mpirun", "renderer",
                    "the ray marcher only (not --renderer slice or segments)");
    switch (s.spec.renderer) {
        case Renderer::Segments: {
            Progress summary("render", 1, "frame");
            render_segments(a.segments, SegmentFrame{a.volume, a.tf, accel, a.threads, s.spec,
                                                     a.out, a.heatmap, a.tf_value});
            std::fflush(stdout);
            summary.done();
            return;
        }
        case Renderer::Slicer: {
            Progress summary("render", 1, "frame");
            render_slice({a.volume, a.tf, accel, a.out, a.threads, s.spec, a.tf_value});
            std::fflush(stdout);
            summary.done();
            return;
        }
        case Renderer::RayMarcher:
            if (mpi_render_active()) {
                // Under mpirun: one frame by every rank (render_mpi.h).
                if (!a.tf_animate.empty() || !a.movie.empty())
                    throw Error("mpirun", "frames",
                                "--orbit and --repeat under mpirun, not --tf-animate or --movie "
                                "yet");
                MpiRenderJob job{a.volume,  front_tf(a), accel,  a.out,
                                 a.heatmap, a.threads,   s.spec, a.mpi};
                for (int i = 0; i < a.orbit; ++i) {
                    job.azimuths.push_back(orbit_azimuth(a.azimuth, i, a.orbit));
                    if (!a.out.empty()) job.outs.push_back(frame_path(a.out, i, a.orbit));
                }
                job.repeat = a.repeat;
                render_mpi(job);
                return;
            }
            if (a.orbit)
                render_orbit(a, s);
            else if (a.tf_animate.empty())
                render_one(a, s);
            else
                render_animation(a, s);
            return;
    }
}

void run(RenderArgs& a) {
    const Setup s = validate(a);
    // The session file's text before any work (what it cannot hold fails now); written after
    // the frame, so a failed render leaves none.
    const std::string session = a.save_session.empty() ? "" : session_text(a, s);
    render_frames(a, s);
    if (!session.empty()) {
        io::write_text_atomic(a.save_session, session);
        std::printf("wrote %s\n", a.save_session.c_str());
    }
}

}  // namespace

void register_render(CLI::App& app) {
    auto a = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand("render", "Render a volume to a PNG");
    add_volume_args(*cmd, a->volume, false);
    cmd->add_flag("--demo", a->demo,
                  "Render the default real dataset (mricron ch2better brain, mr-brain)");
    cmd->add_option("--tf", a->tf, "Transfer function: a preset name or a .json file");
    cmd->add_option("--tf-animate", a->tf_animate,
                    "Two TFs A B: render --frames frames interpolating from A to B and report "
                    "the TF-change time per structure")
        ->expected(2);
    cmd->add_option("--frames", a->frames, "Frames of --tf-animate")->capture_default_str();
    cmd->add_option("--orbit", a->orbit,
                    "Render N frames around the volume: azimuth from --azimuth in steps of 360/N "
                    "degrees, elevation fixed (frames NAME_0000.png, ...)");
    cmd->add_option("--movie", a->movie,
                    "With --orbit or --tf-animate: also write the frames as an H.264 MP4 (needs "
                    "the ffmpeg program; --out then optional)");
    cmd->add_option("--fps", a->fps, "Frames per second of --movie")->capture_default_str();
    cmd->add_option("--session", a->session,
                    "Render the frame a session file describes (volume, TFs, camera, structure, "
                    "features); flags may add only outputs, --orbit/--movie/--fps and --threads");
    cmd->add_option("--save-session", a->save_session,
                    "Also write this frame as a session file (.json) for --session");
    cmd->add_flag("--no-refine", a->no_refine,
                  "Render without the structure's finer per-TF level (the grid's visible-cell "
                  "mask; A/B measurements)");
    cmd->add_option("--repeat", a->repeat,
                    "Render the frame N times in this process; report the median of frames 2..N "
                    "(frame 1 is a warm-up)")
        ->capture_default_str();
    std::string accels;
    for (const auto& n : accel_names()) accels += (accels.empty() ? "" : ", ") + n;
    cmd->add_option("--accel", a->accel,
                    "Empty-space skipping structure: " + accels +
                        " (with --tf-animate also 'all' or a comma-separated list)")
        ->capture_default_str();
    cmd->add_option("--leaf", a->leaf, "Octree leaf edge in cells (2..64, power of two)")
        ->capture_default_str();
    cmd->add_option("--bits", a->bits, "Bitfield width (8, 16, 32, 64, 128)")
        ->capture_default_str();
    cmd->add_option("--initial-level", a->initial_level,
                    "Octree level traversal starts at (-1 = root)")
        ->capture_default_str();
    cmd->add_flag("--top-down", a->top_down, "Octree traversal restarts at the initial level");
    cmd->add_option("--out,-o", a->out, "Output PNG (sequences: NAME_0000.png, ...)");
    cmd->add_option("--heatmap", a->heatmap, "Also write a per-pixel sample-count heat map PNG");
    cmd->add_option("--size", a->size, "Image width and height in pixels")->capture_default_str();
    cmd->add_option("--width", a->width, "Image width (overrides --size)");
    cmd->add_option("--height", a->height, "Image height (overrides --size)");
    cmd->add_option("--azimuth", a->azimuth,
                    "Orbit azimuth in degrees about the patient's superior axis, from the anterior "
                    "view (90: from the left)")
        ->capture_default_str();
    cmd->add_option("--elevation", a->elevation, "Orbit elevation in degrees (toward superior)")
        ->capture_default_str();
    cmd->add_option("--view", a->view, kViewHelp);
    cmd->add_option("--zoom", a->zoom, "Zoom factor (>1 is closer)")->capture_default_str();
    cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
    cmd->add_flag("--ortho", a->ortho, "Orthographic projection");
    cmd->add_option("--step", a->step, "Sample distance in units of the smallest voxel spacing")
        ->capture_default_str();
    cmd->add_option("--interpolation", a->interpolation,
                    "Sampling between voxels: trilinear, or nearest (the voxel a sample falls in; "
                    "bitfield then skips value sets with holes)")
        ->capture_default_str();
    cmd->add_option("--ert", a->ert, "Early ray termination opacity (1 turns it off)")
        ->capture_default_str();
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->capture_default_str();
    cmd->add_option("--background", a->background, "Background colour R,G,B in [0,1]")
        ->capture_default_str();
    add_feature_args(*cmd, a->features);
    add_segment_args(*cmd, a->segments);
    add_slice_options(*cmd, a->slice);
    add_mpi_options(*cmd, a->mpi);
    cmd->callback([a, cmd] {
        a->slice.threshold_given = cmd->count("--occlusion-threshold") > 0;
        a->slice.map_given = cmd->count("--occlusion-map") > 0;
        a->slice.coalesce_given = cmd->count("--coalesce") > 0;
        a->azimuth_given = cmd->count("--azimuth") > 0;
        a->features.given = {cmd->count("--shading") > 0, cmd->count("--phong") > 0,
                             cmd->count("--gradient-opacity") > 0, cmd->count("--blend") > 0};
        a->elevation_given = cmd->count("--elevation") > 0;
        if (!a->session.empty()) {
            // The file is the frame: a flag that would change it is refused, not ignored.
            static const char* const kAllowed[] = {
                "--session", "--out",          "--threads",    "--orbit",     "--movie", "--fps",
                "--quiet",   "--save-session", "--max-memory", "--no-refine", "--repeat"};
            for (const CLI::Option* o : cmd->get_options()) {
                if (o->count() == 0) continue;
                bool ok = false;
                for (const char* n : kAllowed) ok = ok || o->check_lname(n + 2);
                if (!ok)
                    throw Error("--session", "flags",
                                "the session file sets the frame; drop " + o->get_name());
            }
        }
        run(*a);
    });
}

}  // namespace lacuna::cli
