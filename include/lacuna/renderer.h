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
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/image.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

// ---- Optional rendering features (docs/shading.md) -------------------------------------------
// All off by default; with every feature off the renderer runs its fast kernel
// (src/render/ray_march_kernel.h), otherwise the feature kernel (src/render/feature_kernel.h).
// Every feature keeps skipping exact: the structures only drop samples whose TF opacity is
// exactly zero, and every feature below only multiplies or reweights a sample's TF opacity (or
// uses a separately proven bound, MIP/MinIP), so the images stay byte-identical to --accel none.

enum class ShadingModel {
    None,   // TF colour only
    Phong,  // Blinn-Phong: ambient + diffuse*max(N.L,0) + specular*max(N.H,0)^power
    Pbr,    // the bitfield paper's model: Disney diffuse, GGX specular, Smith joint GGX
            // visibility, Schlick Fresnel (Section 4.4, after the Unity Standard Shader)
};
std::string to_string(ShadingModel m);

struct PhongParams {
    float ambient = 0.25f, diffuse = 0.7f, specular = 0.35f, power = 24.f;
};
struct PbrParams {
    float roughness = 0.45f;  // perceptual roughness in (0, 1]; alpha = roughness^2
    float metallic = 0.f;     // 0 dielectric (F0 = 0.04) .. 1 metal (F0 = TF colour)
    float ambient = 0.2f;     // constant ambient term times the TF colour
};

enum class GradientSource {
    OnTheFly,     // the voxels' central differences, interpolated at the sample (core/gradient.h)
    Precomputed,  // central differences per voxel stored as 3 floats, interpolated trilinearly
};

// Gradient-magnitude opacity (VTK's gradient opacity): the TF opacity is multiplied by a
// piecewise-linear function g(|grad|) of the gradient magnitude (voxel values per mm), with the
// TF's rules: linear between points, the end values outside them, and two points at one x a step
// (g takes the second's value at x and right of it). `points` empty: the ramp (lo, 0), (hi, 1),
// i.e. 0 below `lo`, 1 above `hi` (lo == hi a step), --gradient-opacity LO,HI. g only
// multiplies, so the zero set of the modulated opacity contains that of the TF: skipping on the
// TF's zero set stays exact, whatever the points.
struct GradientOpacityPoint {
    float x = 0.f;  // |grad|, voxel values per mm, >= 0
    float a = 0.f;  // factor in [0,1]
    friend bool operator==(const GradientOpacityPoint&, const GradientOpacityPoint&) = default;
};
struct GradientOpacity {
    bool enabled = false;
    float lo = 0.f, hi = 1.f;                  // the ramp, when `points` is empty
    std::vector<GradientOpacityPoint> points;  // sorted by x, at most two per x
};

enum class LightKind {
    Head,         // directional, from the eye along each ray (L = -ray direction)
    Directional,  // from direction `direction` (world, pointing from the volume to the light)
    Spot,         // a point light at `position` aimed at `target`, cone half-angle `cone_deg`
};
std::string to_string(LightKind k);

struct Light {
    LightKind kind = LightKind::Head;
    Vec3f direction{0, 0, 1};
    Vec3f position{0, 0, 0}, target{0, 0, 0};
    float cone_deg = 30.f;  // spot: full intensity inside 0.8*cone, smooth falloff to 0 at cone
    float intensity = 1.f;
};

struct ShadowOptions {
    bool enabled = false;
    // March shadow rays through the skipping structure (exact w.r.t. the unaccelerated shadow
    // rays); false marches every shadow sample (the reference for tests and benchmarks).
    bool accelerate = true;
    float step = 1.f;  // shadow-ray sample distance, in units of the smallest voxel spacing
    // Precompute the transmittance toward the light on a grid of every `light_volume_stride`-th
    // voxel (recomputed when the light or TF changes; its time is in RenderStats) and look it up
    // trilinearly instead of marching a shadow ray per sample.
    bool light_volume = false;
    int light_volume_stride = 2;
};

// A clip plane in world coordinates: points p with dot(normal, p) >= d are kept.
struct ClipPlane {
    Vec3f normal{1, 0, 0};
    float d = 0.f;
};

// BlendMode (composite, MIP, MinIP, average): lacuna/transfer_function.h.

struct FeatureOptions {
    ShadingModel shading = ShadingModel::None;
    PhongParams phong;
    PbrParams pbr;
    GradientSource gradient = GradientSource::OnTheFly;
    GradientOpacity gradient_opacity;
    Light light;
    ShadowOptions shadows;
    std::vector<ClipPlane> clip_planes;
    // With a back TF set on the marcher (RayMarcher::set_back_transfer_function), clip plane 0
    // does not clip: points with dot(n,p) < d use the back TF instead.
    bool crop = false;
    Box3f crop_box{};  // world box [lo, hi]; samples outside are removed
    BlendMode blend = BlendMode::Composite;
    // Jittered ray starts: each pixel's lattice is shifted by a deterministic fraction of a
    // step (a hash of the pixel coordinates), against wood-grain artefacts.
    bool jitter = false;
    uint32_t jitter_seed = 0;
    // True when any feature is on (else the fast kernel runs).
    bool any() const {
        return shading != ShadingModel::None || gradient_opacity.enabled || shadows.enabled ||
               !clip_planes.empty() || crop || blend != BlendMode::Composite || jitter;
    }
};

// Throws lacuna::Error (flag, field, what was expected) for out-of-range feature options.
void validate_features(const FeatureOptions& f);

// "Early termination off": an opacity front-to-back compositing never reaches (accumulated
// opacity stays <= 1). The one number every renderer and bench means by it; FrameSpec's
// Sampling::early_termination = nullopt becomes this (src/session/session.cpp).
inline constexpr float kNoEarlyTermination = 2.f;

// One rank's share of a distributed frame (src/dist/, docs/distributed.md). The marcher's volume
// is then a brick of a larger grid: its voxel (i, j, k) is the whole grid's voxel offset + (i, j,
// k), and it keeps the whole grid's geometry (origin, direction, spacing), so rays, t_near, t_far
// and the lattice t_k are those of the whole grid to the bit. The marcher takes exactly the whole
// grid's lattice samples whose position p (whole index space, the kernel's own float expression
// p = o + t_k * d, before the clamp) has lo[a] <= p[a] < hi[a] on every axis; the bricks' owned
// boxes partition space (the outer faces are -inf / +inf), so every sample of the single-process
// image is taken by exactly one rank. The brick must hold the voxels [lo, hi] of each finite bound
// (the cells an owned sample interpolates in), and [lo - 1, hi + 1] for gradients (shading,
// gradient opacity: their central differences). Early ray termination is off on this path (a
// rank cannot know the opacity in front of its brick); features that act on each sample alone
// are taken, not shadows, blend modes other than composite, or two TFs.
struct BrickOwnership {
    Vec3i whole_dims{0, 0, 0};                   // the whole grid's voxels per axis
    Vec3i offset{0, 0, 0};                       // whole-grid index of the brick's voxel (0, 0, 0)
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // the owned box, whole index space, half open
};
std::string to_string(const BrickOwnership& b);

struct RenderOptions {
    float step = 0.5f;  // sample distance in units of the smallest voxel spacing
    // Trilinear (default) or nearest-neighbour samples (lacuna/accel.h). A structure built for
    // Nearest is rejected with Trilinear (its sets with holes would not be exact).
    Interpolation interpolation = Interpolation::Trilinear;
    float ert = 0.99f;  // early ray termination opacity; >= 1 turns it off (kNoEarlyTermination)
    int threads = 0;    // 0 = all hardware threads
    Vec3f background{0, 0, 0};
    bool count_samples = false;  // fill RenderResult::sample_counts (for --heatmap)
    bool keep_float = false;     // fill RenderResult::rgba_float (tests, error bounds)
    int tile = 16;               // tile edge in pixels (work unit of the thread pool)
    FeatureOptions features;     // shading, lighting, clipping, blend modes, jitter
    // Distributed rendering: this rank's brick and owned box (nullptr: the whole volume, the
    // single-process path, untouched).
    const BrickOwnership* brick = nullptr;
};

struct RenderStats {
    double seconds = 0;
    double cpu_seconds = 0;  // CPU time of the whole process (all threads) during the frame
    uint64_t samples = 0;    // samples taken
    uint64_t rays = 0;       // rays that hit the volume's box
    uint64_t pixels = 0;
    uint64_t shadow_samples = 0;         // samples of shadow rays and light-volume rays
    size_t gradient_volume_bytes = 0;    // memory of the precomputed gradient volume (0: none)
    double gradient_volume_seconds = 0;  // its computation in this render (0: cached or none)
    size_t light_volume_bytes = 0;       // memory of the light volume (0: none)
    double light_volume_seconds = 0;     // its computation in this render (0: cached or none)
    double msamples_per_second() const {
        return seconds > 0 ? double(samples) / seconds * 1e-6 : 0;
    }
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};
std::string to_string(const RenderStats& s);

struct RenderResult {
    Image image;
    std::vector<uint32_t> sample_counts;  // per pixel, when RenderOptions::count_samples
    std::vector<float> rgba_float;        // per pixel premultiplied RGBA before the background and
                                          // 8-bit rounding, when RenderOptions::keep_float
    RenderStats stats;
};

class RayMarcher {
  public:
    // The volume must outlive the marcher. Its vis_range defines the TF domain.
    explicit RayMarcher(const Volume& volume);
    ~RayMarcher();
    void set_transfer_function(const TransferLut& lut);
    // The TF on the back side of clip plane 0 (FeatureOptions): an empty LUT turns it off. It
    // must have the same size and visualization range as the front TF. The skipping structure
    // must then be given union_lut(front, back), so it skips only where both are transparent.
    void set_back_transfer_function(const TransferLut& lut);
    // The skipping structure to use (nullptr: none). It must outlive the marcher's renders and
    // already have the current TF (Accel::set_transfer_function).
    void set_accel(const Accel* accel) { m_accel = accel; }
    RenderResult render(const Camera& camera, const RenderOptions& options) const;
    // World box of the volume: [0, (dims-1)*spacing].
    Box3f bounds() const;

  private:
    RenderResult render_features(const Camera& camera, const RenderOptions& options) const;
    struct Cache;  // precomputed gradient and light volumes (src/render/ray_marcher.cpp)
    const Volume& m_volume;
    TransferLut m_lut, m_back_lut;
    const Accel* m_accel = nullptr;
    std::unique_ptr<Cache> m_cache;
    uint64_t m_tf_version = 0;
};

// The LUT a skipping structure needs for two TFs: colour of `a`, opacity max(a, b) per entry,
// so an entry is transparent exactly where both are. Throws lacuna::Error if the LUTs differ in
// size or visualization range.
TransferLut union_lut(const TransferLut& a, const TransferLut& b);

// The premultiplied, step-corrected table the kernels read: entry e is
// (r*a', g*a', b*a', a') with a' = 1 - (1 - a)^step (opacity correction, `step` in units of
// the distance the TF's opacity is defined for: one smallest voxel spacing).
std::vector<Rgba> step_corrected_lut(const TransferLut& lut, float step);

}  // namespace lacuna
