#include "render_slice.h"

#include <cstdio>

#include "core/parallel.h"
#include "lacuna/error.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"

namespace lacuna::cli {

void add_slice_options(CLI::App& cmd, SliceCliArgs& a) {
    cmd.add_option("--renderer", a.renderer,
                   "march (ray marcher) or slice (object-order slicer, docs/slicer.md)")
        ->capture_default_str();
    cmd.add_flag("--occlusion", a.occlusion,
                 "Slicer: occlusion culling and clipping against the opacity map");
    cmd.add_option("--occlusion-threshold", a.occlusion_threshold,
                   "Slicer: opacity at which the map counts a cell as occluded (1 = exact)")
        ->capture_default_str();
    cmd.add_option("--occlusion-map", a.occlusion_map, "Slicer: opacity map edge in cells")
        ->capture_default_str();
    cmd.add_option("--coalesce", a.coalesce,
                   "Slicer, --accel boxes: render a BSP subtree as one box when at most this "
                   "share of it is empty (exact for any value; negative: every leaf alone)")
        ->capture_default_str();
    cmd.add_option(
           "--coalesce-edge", a.coalesce_edge,
           "Slicer, --accel boxes: largest box --coalesce makes, per axis in world units (mm)")
        ->capture_default_str();
}

void check_slice_options(const SliceCliArgs& a, bool animate, bool heatmap) {
    if (a.renderer != "march" && a.renderer != "slice")
        throw Error("--renderer", "renderer", "expected march or slice, got '" + a.renderer + "'");
    if (a.renderer == "march") {
        if (a.occlusion || a.threshold_given || a.map_given)
            throw Error("--occlusion", "renderer",
                        "occlusion clipping belongs to the slicer: add --renderer slice");
        if (a.coalesce_given || a.coalesce_edge != BoxesOptions{}.coalesce_edge)
            throw Error("--coalesce", "renderer", "belongs to the slicer: add --renderer slice");
        return;
    }
    if (animate) throw Error("--tf-animate", "renderer", "only with --renderer march");
    if (heatmap) throw Error("--heatmap", "renderer", "only with --renderer march");
    if ((a.threshold_given || a.map_given) && !a.occlusion)
        throw Error("--occlusion-threshold", "occlusion", "needs --occlusion");
    if (!(a.occlusion_threshold > 0.f && a.occlusion_threshold <= 1.f))
        throw Error("--occlusion-threshold", "threshold", "expected 0 < T <= 1");
    if (a.occlusion_map < 1 || a.occlusion_map > 4096)
        throw Error("--occlusion-map", "map size", "expected 1..4096 cells");
}

void render_slice(const SliceRenderJob& job) {
    const TransferFunction tf = job.tf_value ? *job.tf_value : resolve_transfer_function(job.tf);
    Session session(load_volume(job.volume), job.threads);
    session.set_transfer_function(tf);
    Progress progress("building " + job.accel);
    session.prepare(job.spec);
    progress.done();
    const FrameResult r = session.render(job.spec);
    write_png(job.out, r.image);
    const SlicerFrameStats& s = *r.slicer;
    const FrameSpec& f = job.spec;
    std::printf(
        "%s: %dx%d %s, tf %s, slice renderer, accel %s, %d threads\n", job.volume.path.c_str(),
        f.width, f.height,
        f.camera.orbit.projection == Projection::Orthographic ? "orthographic" : "perspective",
        tf.name.c_str(), job.accel.c_str(), resolve_threads(job.threads));
    std::printf(
        "render time %.1f ms (polygon set-up %.1f%% of CPU time, %.1f%% of wall time), "
        "%llu boxes, %llu polygons, %.1f Msamples/s\n",
        r.stats.seconds * 1e3, 100 * s.setup_cpu_fraction, 100 * s.setup_fraction,
        (unsigned long long)s.boxes, (unsigned long long)s.polygons,
        r.stats.seconds > 0 ? double(r.stats.samples) / r.stats.seconds * 1e-6 : 0);
    if (f.slicer.occlusion)
        std::printf(
            "occlusion (threshold %.3g, map %dx%d): %d/%d map updates, %llu boxes culled, "
            "%llu clipped, %.1f%% of non-empty voxels skipped (%.1f%% culled, %.1f%% "
            "clipped), %.1f ms\n",
            f.slicer.occlusion_threshold, f.slicer.occlusion_map, f.slicer.occlusion_map,
            s.map_updates, s.desired_updates, (unsigned long long)s.boxes_culled,
            (unsigned long long)s.boxes_clipped, 100 * s.skipped_fraction, 100 * s.culled_fraction,
            100 * s.clipped_fraction, s.occlusion_seconds * 1e3);
    std::printf("wrote %s\n", job.out.c_str());
}

}  // namespace lacuna::cli
