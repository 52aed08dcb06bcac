// The benchmark orbit: N views around the volume's up axis (the paper's "rotating around the
// vertical axis through its center"), and a runner that renders all of them through a Session
// (lacuna/session.h), as every front end renders: the benches build FrameSpecs, the session
// builds, TF-syncs and keeps the structures.
#pragma once
#include <cstdint>
#include <vector>

#include "lacuna/camera.h"
#include "lacuna/frame_spec.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"

namespace lacuna::bench {

struct OrbitSpec {
    int views = 36;              // view i at azimuth 360 * i / views
    int size = 1024;             // square image edge in pixels
    float elevation_deg = 20.f;  // fixed for every view
};

// The orbit's frames: `base` with a spec.size square image and view i's orbit (azimuth
// 360 * i / views, the elevation; the rest of base.camera.orbit kept): Camera::orbit's default
// framing of the session's bounds, perspective, view 0 at azimuth 0.
std::vector<FrameSpec> orbit_frames(const FrameSpec& base, const OrbitSpec& spec);

struct OrbitRun {
    std::vector<double> frame_seconds;  // per view, RenderStats::seconds
    uint64_t samples = 0, rays = 0;     // summed over the views
    Image first_image;                  // view 0 (the exactness check)
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};

// Renders every frame through `session` (the first one builds what the frames need, outside
// the frame times: call session.prepare(frames[0]) first to time that on its own).
OrbitRun run_orbit(Session& session, const std::vector<FrameSpec>& frames);

}  // namespace lacuna::bench
