#include "bench/orbit.h"

#include <utility>

#include "lacuna/error.h"

namespace lacuna::bench {

namespace {

void check(const OrbitSpec& spec) {
    if (spec.views < 1) throw Error("--views", "views", "expected at least 1");
    if (spec.size < 1 || spec.size > 16384)
        throw Error("--size", "image size", "expected 1..16384 pixels per side");
}

// View i's orbit: the one formula of both forms below.
OrbitParams view(OrbitParams p, const OrbitSpec& spec, int i) {
    p.azimuth_deg = 360.f * float(i) / float(spec.views);
    p.elevation_deg = spec.elevation_deg;
    return p;
}

}  // namespace

std::vector<FrameSpec> orbit_frames(const FrameSpec& base, const OrbitSpec& spec) {
    check(spec);
    std::vector<FrameSpec> out(size_t(spec.views), base);
    for (int i = 0; i < spec.views; ++i) {
        FrameSpec& f = out[size_t(i)];
        f.width = f.height = spec.size;
        f.camera.orbit = view(base.camera.orbit, spec, i);
    }
    return out;
}

namespace {

void add(OrbitRun& run, size_t v, RenderStats stats, Image&& image) {
    run.frame_seconds.push_back(stats.seconds);
    run.samples += stats.samples;
    run.rays += stats.rays;
    if (v == 0) run.first_image = std::move(image);
}

}  // namespace

OrbitRun run_orbit(Session& session, const std::vector<FrameSpec>& frames) {
    OrbitRun run;
    run.frame_seconds.reserve(frames.size());
    for (size_t v = 0; v < frames.size(); ++v) {
        FrameResult r = session.render(frames[v]);
        add(run, v, r.stats, std::move(r.image));
    }
    return run;
}

}  // namespace lacuna::bench
