#include "render_mpi.h"

#include <algorithm>
#include <cstdio>

#include "core/parallel.h"
#include "dist/comm.h"
#include "dist/distributed_frame.h"
#include "io/brick_read.h"
#include "lacuna/error.h"

namespace lacuna::cli {

namespace {

dist::Balance parse_balance(const std::string& s) {
    if (s == "voxels") return dist::Balance::Voxels;
    if (s == "visible") return dist::Balance::Visible;
    throw Error("--balance", "balance", "expected voxels or visible, got '" + s + "'");
}

dist::Composite parse_composite(const std::string& s) {
    if (s == "direct") return dist::Composite::Direct;
    if (s == "binary-swap") return dist::Composite::BinarySwap;
    if (s == "radix-k") return dist::Composite::RadixK;
    throw Error("--composite", "compositing",
                "expected direct, binary-swap or radix-k, got '" + s + "'");
}

}  // namespace

void add_mpi_options(CLI::App& cmd, MpiCliArgs& a, bool rank_times) {
    cmd.add_option("--balance", a.balance,
                   "Under mpirun: kd-tree bricks balanced on voxels, or on the cells the TF can "
                   "make visible (docs/distributed.md)")
        ->capture_default_str();
    cmd.add_option(
           "--composite", a.composite,
           "Under mpirun: sort-last compositing, direct (to rank 0), binary-swap or radix-k "
           "(k = 4)")
        ->capture_default_str();
    if (rank_times)
        cmd.add_flag(
            "--rank-times", a.rank_times,
            "Under mpirun: rank 0 prints each rank's load, build, render and composite times");
}

bool mpi_render_active() {
    return dist::launched();
}

void check_mpi_options(const MpiCliArgs& a) {
    parse_balance(a.balance);
    parse_composite(a.composite);
}

dist::DistOptions dist_options(const MpiCliArgs& a) {
    dist::DistOptions o;
    o.balance = parse_balance(a.balance);
    o.composite = parse_composite(a.composite);
    return o;
}

void check_distributable(const FrameSpec& spec) {
    if (spec.renderer != Renderer::RayMarcher)
        throw Error("mpirun", "renderer", "the ray marcher only (not the slicer or segments)");
    // Shading, gradient opacity, clip planes, crop and jitter act on each sample alone; shadows
    // reach into other bricks, and the other blend modes and a back TF composite differently.
    const FeatureOptions& f = spec.features;
    if (f.shadows.enabled || f.blend != BlendMode::Composite || spec.two_tfs)
        throw Error("mpirun", "features",
                    "distributed rendering takes no shadows, blend modes or --tf-back yet");
}

dist::VolumeSource volume_source(const VolumeArgs& v) {
    // Files whose voxels lie at an offset are read by offset (each rank its brick,
    // src/io/brick_read.h), every other file whole by each rank. The header is every rank's
    // alike: its errors (a truncated file) are thrown here, before any rank waits for another.
    ReadOptions ro;
    ro.raw = v.raw_spec ? v.raw_spec : raw_spec_of(v);
    ro.frame = v.frame;
    if (!v.max_memory.empty()) ro.max_memory.bytes = parse_bytes(v.max_memory, "--max-memory");
    ro.max_memory.name = "--max-memory";
    ro.allow_external_data = v.allow_external_data;
    dist::VolumeSource source;
    source.load_whole = [v] { return load_volume(v); };
    source.file = io::open_brick_file(v.path, ro);
    source.budget = ro.max_memory;
    if (v.range_value)
        source.vis_range = v.range_value;
    else if (!v.range.empty())
        source.vis_range = parse_range(v.range);
    return source;
}

void render_mpi(const MpiRenderJob& job) {
    dist::Comm& comm = dist::Comm::world();
    const dist::DistOptions o = dist_options(job.mpi);
    // What every rank refuses alike, before any rank starts (one line from rank 0, main.cpp).
    check_distributable(job.spec);
    const dist::VolumeSource source = volume_source(job.volume);
    // Rank 0 alone writes; a failed write there ends the job (the others may already wait in
    // the next frame's messages).
    auto write_or_end = [&](const std::string& path, const Image& image) {
        try {
            write_png(path, image);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "lacuna: %s\n", e.what());
            comm.abort(2);
        }
    };
    dist::DistFrame f;  // the frame the report describes
    double orbit_seconds = 0;
    try {
        dist::DistributedSession session(comm, source, job.tf, o, job.threads);
        if (!job.azimuths.empty()) {
            // --orbit: every frame from the same bricks and structures.
            FrameSpec spec = job.spec;
            for (size_t i = 0; i < job.azimuths.size(); ++i) {
                spec.camera.orbit.azimuth_deg = job.azimuths[i];
                f = session.render(job.tf, spec, /*refine=*/i == 0);
                orbit_seconds += f.frame_seconds;
                if (comm.rank() == 0 && i < job.outs.size()) write_or_end(job.outs[i], f.image);
            }
        } else {
            f = session.render(job.tf, job.spec, /*refine=*/true);
            // --repeat N: frame 1 warms caches, pages and threads; the report is the median of
            // the N - 1 frames after it by rank 0's frame time (every frame the same bytes).
            std::vector<dist::DistFrame> warm;
            for (int r = 1; r < job.repeat; ++r) warm.push_back(session.render(job.tf, job.spec));
            if (!warm.empty()) {
                std::sort(warm.begin(), warm.end(),
                          [](const dist::DistFrame& a, const dist::DistFrame& b) {
                              return a.frame_seconds < b.frame_seconds;
                          });
                f = std::move(warm[warm.size() / 2]);
            }
        }
    } catch (const dist::RankFailure& e) {
        // One rank's own failure while rendering: the others may wait for its messages, so the
        // job ends here with the CLI's exit code for errors.
        std::fprintf(stderr, "lacuna: %s\n", e.what());
        comm.abort(2);
    }
    if (comm.rank() != 0) return;
    if (job.azimuths.empty()) write_png(job.out, f.image);
    if (!job.heatmap.empty())
        write_png(job.heatmap, heatmap(f.sample_counts, job.spec.width, job.spec.height));
    const FrameSpec& s = job.spec;
    uint64_t samples = 0, rays = 0, voxels = 0, bytes = 0;
    double slowest = 0;
    for (const auto& r : f.ranks) {
        samples += r.samples, rays = std::max<uint64_t>(rays, r.rays), voxels += r.voxels;
        bytes += r.bytes_sent;
        slowest = std::max(slowest, r.render_seconds);
    }
    std::printf(
        "%s: %dx%d %s, tf %s, accel %s, %d ranks (%s, %s compositing), %d threads per rank\n",
        job.volume.path.c_str(), s.width, s.height,
        s.camera.orbit.projection == Projection::Orthographic ? "orthographic" : "perspective",
        job.tf.name.c_str(), job.accel.c_str(), comm.size(), dist::to_string(o.balance).c_str(),
        dist::to_string(o.composite).c_str(), dist::rank_threads(job.threads));
    if (s.sampling.early_termination)
        std::printf(
            "early ray termination: off (a rank cannot see the opacity in front of its brick)\n");
    std::printf("bricks: %s\n", dist::to_string(f.decomposition).c_str());
    if (!job.azimuths.empty())
        std::printf("orbit of %zu frames, frame time %.1f ms (mean); the last frame:\n",
                    job.azimuths.size(), orbit_seconds / double(job.azimuths.size()) * 1e3);
    else if (job.repeat > 1)
        std::printf("%d frames; the median of the %d after the first:\n", job.repeat,
                    job.repeat - 1);
    std::printf(
        "frame %.1f ms (slowest rank's render %.1f ms), %llu samples, %.1f MiB composited\n",
        f.frame_seconds * 1e3, slowest * 1e3, (unsigned long long)samples,
        double(bytes) / (1 << 20));
    if (job.mpi.rank_times) {
        std::printf("%4s %9s %9s %10s %12s %10s %12s %8s %8s %10s %9s\n", "rank", "load ms",
                    "build ms", "render ms", "composite ms", "CPU ms", "samples", "voxels%",
                    "read%", "sent KiB", "peak MiB");
        for (const auto& r : f.ranks)
            std::printf(
                "%4d %9.1f %9.1f %10.1f %12.1f %10.1f %12llu %8.1f %8.1f %10.1f %9.1f\n", r.rank,
                r.load_seconds * 1e3, r.build_seconds * 1e3, r.render_seconds * 1e3,
                r.composite_seconds * 1e3, r.cpu_seconds * 1e3, (unsigned long long)r.samples,
                100.0 * double(r.voxels) / double(std::max<uint64_t>(f.whole_voxels, 1)),
                100.0 * double(r.voxels_read) / double(std::max<uint64_t>(f.whole_voxels, 1)),
                double(r.bytes_sent) / 1024, double(r.peak_rss_kib) / 1024);
    }
    if (!job.heatmap.empty()) std::printf("wrote %s\n", job.heatmap.c_str());
    if (!job.outs.empty())
        std::printf("wrote %s .. %s\n", job.outs.front().c_str(), job.outs.back().c_str());
    else if (job.azimuths.empty())
        std::printf("wrote %s\n", job.out.c_str());
    std::fflush(stdout);
}

}  // namespace lacuna::cli
