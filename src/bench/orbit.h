// The benchmark orbit: N views around the volume's up axis (the paper's "rotating around the
// vertical axis through its center"), and a runner that renders all of them with one setup.
#pragma once
#include <cstdint>
#include <vector>

#include "lacuna/camera.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"

namespace lacuna::bench {

struct OrbitSpec {
    int views = 36;              // view i at azimuth 360 * i / views
    int size = 1024;             // square image edge in pixels
    float elevation_deg = 20.f;  // fixed for every view
};

// Cameras framing `bounds` (Camera::orbit's default framing), perspective, view 0 at azimuth 0.
std::vector<Camera> orbit_cameras(const Box3f& bounds, const OrbitSpec& spec);

struct OrbitRun {
    std::vector<double> frame_seconds;  // per view, RenderStats::seconds
    uint64_t samples = 0, rays = 0;     // summed over the views
    Image first_image;                  // view 0 (the exactness check)
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};

// Renders every camera with `marcher` as it is set up (TF, structure).
OrbitRun run_orbit(const RayMarcher& marcher, const std::vector<Camera>& cameras,
                   const RenderOptions& options);

}  // namespace lacuna::bench
