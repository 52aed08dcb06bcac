#include "bench/orbit.h"

#include <utility>

#include "lacuna/error.h"

namespace lacuna::bench {

std::vector<Camera> orbit_cameras(const Box3f& bounds, const OrbitSpec& spec) {
    if (spec.views < 1) throw Error("--views", "views", "expected at least 1");
    if (spec.size < 1 || spec.size > 16384)
        throw Error("--size", "image size", "expected 1..16384 pixels per side");
    std::vector<Camera> out;
    out.reserve(size_t(spec.views));
    for (int i = 0; i < spec.views; ++i) {
        OrbitParams p;
        p.azimuth_deg = 360.f * float(i) / float(spec.views);
        p.elevation_deg = spec.elevation_deg;
        out.push_back(Camera::orbit(bounds, p, spec.size, spec.size));
    }
    return out;
}

OrbitRun run_orbit(const RayMarcher& marcher, const std::vector<Camera>& cameras,
                   const RenderOptions& options) {
    OrbitRun run;
    run.frame_seconds.reserve(cameras.size());
    for (size_t v = 0; v < cameras.size(); ++v) {
        RenderResult r = marcher.render(cameras[v], options);
        run.frame_seconds.push_back(r.stats.seconds);
        run.samples += r.stats.samples;
        run.rays += r.stats.rays;
        if (v == 0) run.first_image = std::move(r.image);
    }
    return run;
}

}  // namespace lacuna::bench
