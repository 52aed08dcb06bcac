// The reference renderer: a CPU ray marcher (emission-absorption, front to back).
//
// Sample lattice (the contract every skipping structure relies on): a ray enters the volume's
// box [0, dims-1]*spacing at t_near (0 if the eye is inside) and leaves at t_far; its samples
// are at
//     t_k = t_near + (k + 0.5) * dt,   k = 0, 1, ...  while t_k < t_far
// with dt = step * min(spacing). A structure that skips may only drop samples whose TF opacity
// is exactly zero; resumed marching uses the same k, so every kept sample is computed with the
// same arithmetic as in the unaccelerated image and the pictures are byte-identical.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/image.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

struct RenderOptions {
    float step = 0.5f;        // sample distance in units of the smallest voxel spacing
    float ert = 0.99f;        // early ray termination opacity; >= 1 turns it off
    int threads = 0;          // 0 = all hardware threads
    Vec3f background{0, 0, 0};
    bool count_samples = false;  // fill RenderResult::sample_counts (for --heatmap)
    bool keep_float = false;     // fill RenderResult::rgba_float (tests, error bounds)
    int tile = 16;               // tile edge in pixels (work unit of the thread pool)
};

struct RenderStats {
    double seconds = 0;
    uint64_t samples = 0;   // trilinear samples taken
    uint64_t rays = 0;      // rays that hit the volume's box
    uint64_t pixels = 0;
    double msamples_per_second() const { return seconds > 0 ? double(samples) / seconds * 1e-6 : 0; }
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};
std::string to_string(const RenderStats& s);

struct RenderResult {
    Image image;
    std::vector<uint32_t> sample_counts;  // per pixel, when RenderOptions::count_samples
    std::vector<float> rgba_float;  // per pixel premultiplied RGBA before the background and
                                    // 8-bit rounding, when RenderOptions::keep_float
    RenderStats stats;
};

class RayMarcher {
public:
    // The volume must outlive the marcher. Its vis_range defines the TF domain.
    explicit RayMarcher(const Volume& volume);
    ~RayMarcher();
    void set_transfer_function(const TransferLut& lut);
    // The skipping structure to use (nullptr: none). It must outlive the marcher's renders and
    // already have the current TF (Accel::set_transfer_function).
    void set_accel(const Accel* accel) { m_accel = accel; }
    RenderResult render(const Camera& camera, const RenderOptions& options) const;
    // World box of the volume: [0, (dims-1)*spacing].
    Box3f bounds() const;

private:
    const Volume& m_volume;
    TransferLut m_lut;
    const Accel* m_accel = nullptr;
};

// The premultiplied, step-corrected table the kernels read: entry e is
// (r*a', g*a', b*a', a') with a' = 1 - (1 - a)^step (opacity correction, `step` in units of
// the distance the TF's opacity is defined for: one smallest voxel spacing).
std::vector<Rgba> step_corrected_lut(const TransferLut& lut, float step);

}  // namespace lacuna
