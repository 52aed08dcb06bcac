// FrameSpec: one closed, typed description of a frame, and the one table of what each renderer
// accepts (STYLE.md habit 11).
//
// Why one description. Three renderers (the ray marcher, the object-order slicer, the segment
// renderer) and two front ends (the CLI, the viewer) used to wire volume -> TF -> structure ->
// renderer by hand, each deciding on its own which renderer takes which structure and feature.
// A frame is now a value: which renderer, which structure with its parameters, how to sample,
// which features, the camera and the image. A front end turns its strings into a FrameSpec at its
// edge and hands it to lacuna::Session (lacuna/session.h); nothing below it wires anything.
//
// Why a variant per structure. Each structure reads its own parameters (an octree its leaf edge
// and traversal, the bitfield its width, the distance maps their block, the kd-tree its split
// rules, growing boxes their coalescing); a flat struct lets a caller set a field no renderer
// reads. `Structure` is a std::variant, so a spec names exactly one structure and carries exactly
// its parameters; the session builds one per distinct value and keeps it across frames.
//
// Why a table. Whether a renderer takes a structure or a feature is a fact about the renderer,
// not about a front end: `capabilities()` states it once, `validate()` checks a spec against it,
// and the viewer sends it to the page (docs/viewer.md) instead of the page hard-coding rules.
//
// Errors name fields ("sampling.step", "structure", "features.clip_planes"): validate() throws
// FrameError, whose `field` a front end translates to its own vocabulary (the CLI to its flags,
// apps/lacuna/frame_flags.cpp). The library never names a CLI flag here.
#pragma once
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/error.h"
#include "lacuna/math.h"
#include "lacuna/renderer.h"
#include "lacuna/segments.h"

namespace lacuna {

// ---- Renderers ----------------------------------------------------------------------------------
enum class Renderer {
    RayMarcher,  // image order, the reference (lacuna/renderer.h); every skipping structure
    Slicer,      // object order: view-aligned slices of boxes in visibility order (docs/slicer.md)
    Segments,    // a label map, alone or masking the intensity (lacuna/segments.h)
};
std::string to_string(Renderer r);

// ---- Structures and their parameters ------------------------------------------------------------
// One alternative per structure; each carries only what that structure reads. Defaults are the
// ones every front end has used (AccelOptions, BoxesOptions, SegmentOptions).
namespace structure {

// Octree traversal shared by the value octrees.
struct Octree {
    int leaf_cells = 8;         // leaf edge in cells (2..64, power of two)
    int initial_level = -1;     // level traversal starts at (-1 = the root)
    bool bidirectional = true;  // traversal moves up and down (false: top-down only)
    friend bool operator==(const Octree&, const Octree&) = default;
};

struct None {  // every lattice sample (the reference); the slicer: the whole volume as one box
    friend bool operator==(const None&, const None&) = default;
};
struct MinMax {
    Octree octree;
    friend bool operator==(const MinMax&, const MinMax&) = default;
};
struct MinMaxInterval {
    Octree octree;
    friend bool operator==(const MinMaxInterval&, const MinMaxInterval&) = default;
};
struct Bitfield {
    Octree octree;
    int bits = 64;  // 8, 16, 32, 64 or 128
    friend bool operator==(const Bitfield&, const Bitfield&) = default;
};
struct Boolean {
    Octree octree;
    friend bool operator==(const Boolean&, const Boolean&) = default;
};
struct Distance {   // Euclidean
    int block = 4;  // cells per map voxel
    friend bool operator==(const Distance&, const Distance&) = default;
};
struct Chebyshev {
    int block = 4;
    friend bool operator==(const Chebyshev&, const Chebyshev&) = default;
};
struct KdTree {
    int max_boxes = 0;        // M, most subvolumes in the list (0 = every leaf)
    int delta = 0;            // candidate plane spacing in cells (0 = from size)
    float min_volume = 0.1f;  // nodes below this fraction of the grid are leaves
    float min_gain = 0.05f;   // a split must remove this fraction of its node
    int max_depth = 10;       // deepest split level (root = 0)
    friend bool operator==(const KdTree&, const KdTree&) = default;
};
struct Grid {  // the brick grid (the default: default_accel())
    friend bool operator==(const Grid&, const Grid&) = default;
};
// Growing boxes ordered by their BSP tree (the slicer only; docs/growing-boxes.md).
struct GrowingBoxes {
    float coalesce = 0.25f;      // BoxesOptions::coalesce
    float coalesce_edge = 64.f;  // BoxesOptions::coalesce_edge (mm)
    friend bool operator==(const GrowingBoxes&, const GrowingBoxes&) = default;
};
// The label bitfield octree (the segment renderer only): labels and intensity bins per node.
struct LabelOctree {
    int leaf_cells = 8;
    int bits = 64;  // mask mode: the intensity bitfield's width
    friend bool operator==(const LabelOctree&, const LabelOctree&) = default;
};

}  // namespace structure

// In the order of src/session/structure_registry.h (one entry per alternative): the order
// accel_names(), the benchmarks' columns and the capabilities table's rows list them in.
using Structure = std::variant<structure::None, structure::Distance, structure::Chebyshev,
                               structure::Boolean, structure::MinMax, structure::Bitfield,
                               structure::KdTree, structure::MinMaxInterval, structure::Grid,
                               structure::GrowingBoxes, structure::LabelOctree>;

// The structure's name: an accel_names() entry, "boxes" or "label-octree".
std::string structure_name(const Structure& s);
// The structure a front end's name names for renderer `r`: the one parser of `--accel`, the
// viewer's "accel" and Python's structure=. "auto" is the renderer's default (the brick grid for
// the ray marcher, the whole volume for the slicer, the label octree for the segment renderer);
// the segment renderer's "bitfield" is its label octree; "boxes" the growing boxes; every other
// name an accel_names() entry with its parameters from `o`. Throws FrameError("structure", ...)
// listing the names for an unknown one (whether `r` takes it is validate()'s question).
Structure parse_structure(const std::string& name, Renderer r, const AccelOptions& o = {},
                          const structure::GrowingBoxes& boxes = {});
// The ray-marching structures as AccelKind (GrowingBoxes and LabelOctree have none).
std::optional<AccelKind> accel_kind(const Structure& s);
// The structure of kind `k` with its parameters taken from `o` (the typed options the front
// ends already hold).
Structure structure_of(AccelKind k, const AccelOptions& o = {});
// The AccelOptions make_accel needs for `s` (nullopt: not a ray-marching structure).
std::optional<AccelOptions> accel_options(const Structure& s, Interpolation interpolation,
                                          int threads);
// One value of every alternative, in variant order, with default parameters (the table's rows).
std::vector<Structure> all_structures();

// ---- The frame ----------------------------------------------------------------------------------
struct Sampling {
    float step = 0.5f;  // in units of the smallest voxel spacing, (0, 64]
    // Early ray termination at this accumulated opacity, in (0, 1); nullopt marches every ray to
    // its end (what `--ert 1` means).
    std::optional<float> early_termination = 0.99f;
    Interpolation interpolation = Interpolation::Trilinear;
};

// What the slicer does with its opacity map (growing-boxes paper, Section 4): the method culls
// and clips boxes against it; the other two are the paper's ablations (its ESS+C and ESS+M).
enum class OcclusionUse {
    CullClip,  // cull hidden boxes, clip the rest to their visible part
    CullOnly,  // cull only
    MapOnly,   // every map update and box test, nothing skipped: the map's overhead alone
};

struct SlicerSpec {
    bool occlusion = false;             // occlusion culling and clipping against the opacity map
    float occlusion_threshold = 0.95f;  // (0, 1]; 1 is exact
    int occlusion_map = 64;             // map edge in cells, 1..4096
    OcclusionUse occlusion_use = OcclusionUse::CullClip;
    int occlusion_updates = 9;  // map updates per frame (k), >= 0
    // Section 4.4's controller picks the updates per frame instead, from occlusion_updates on,
    // learning from the frame before. It learns over the session's consecutive frames with this
    // structure and slicer spec; any other frame in between starts it afresh.
    bool adaptive_updates = false;
    friend bool operator==(const SlicerSpec&, const SlicerSpec&) = default;
};

struct SegmentsSpec {
    SegmentMode mode = SegmentMode::Masked;
    float tint = 0.f;  // mask mode: weight of the label colour against the TF colour, [0, 1]
    // Per-label colour, opacity, visibility; nullopt: the session's default table
    // (Session::label_table()).
    std::optional<LabelTable> labels;
};

struct CameraSpec {
    OrbitParams orbit;
    // Moves the orbit's target along the view plane (the orbit camera's right and up), in units
    // of the bounding sphere's radius (the viewer's drag). Zero leaves the orbit as it is.
    float pan_x = 0.f, pan_y = 0.f;
};

struct FrameSpec {
    Renderer renderer = Renderer::RayMarcher;
    Structure structure = structure::Grid{};
    Sampling sampling;
    // Shading, lights, shadows, clip planes, crop, blend modes, jitter (the ray marcher only).
    FeatureOptions features;
    // The session's back TF behind clip plane 0 (Session::set_back_transfer_function); the ray
    // marcher only, and it needs a clip plane.
    bool two_tfs = false;
    SlicerSpec slicer;
    SegmentsSpec segments;
    CameraSpec camera;
    int width = 512, height = 512;  // 1..16384
    Vec3f background{0, 0, 0};      // linear RGB in [0, 1]
    bool count_samples = false;     // per-pixel sample counts (a heat map)
    bool keep_float = false;        // FrameResult::rgba_float: the RGBA before 8-bit rounding
};

// ---- Capabilities -------------------------------------------------------------------------------
// What a renderer can do beyond the common part (step, camera, image, background).
enum class Feature {
    Shading,           // features.shading, lights
    GradientOpacity,   // features.gradient_opacity
    Shadows,           // features.shadows
    ClipPlanes,        // features.clip_planes
    Crop,              // features.crop
    Blend,             // features.blend other than Composite
    Jitter,            // features.jitter
    TwoTfs,            // two_tfs
    Nearest,           // sampling.interpolation Nearest
    EarlyTermination,  // sampling.early_termination set
    SampleCounts,      // count_samples
    Occlusion,         // slicer.occlusion
};
std::string to_string(Feature f);
std::vector<Feature> all_features();

struct RendererCapabilities {
    Renderer renderer;
    std::vector<std::string> structures;  // structure_name()s it takes
    std::vector<Feature> features;
    // Structures only the segment renderer's mask mode takes (the intensity structures: in
    // labels mode there is no intensity to skip on).
    std::vector<std::string> masked_only_structures;
    bool takes(const Structure& s) const;
    bool has(Feature f) const;
};
// One row per renderer, in enum order.
const std::vector<RendererCapabilities>& capabilities();
const RendererCapabilities& capabilities(Renderer r);

// ---- A TF's rendering ---------------------------------------------------------------------------
// A TF may carry the rendering it was made for (TfRendering, lacuna/transfer_function.h: 3D
// Slicer's shading terms and gradient opacity, a MIP preset's blend). It is a default, not an
// order: each part applies only where the user did not set the feature and the renderer takes it
// (capabilities(); the slicer and the segment renderer take none of them).
struct TfRenderingOverrides {       // true: the user set it, the TF's rendering leaves it alone
    bool shading = false;           // the model (features.shading; the CLI's --shading)
    bool phong = false;             // the Phong terms (features.phong; --phong)
    bool gradient_opacity = false;  // features.gradient_opacity (--gradient-opacity)
    bool blend = false;             // features.blend (--blend)
};
// Sets spec.features from r, part by part:
//   r.shading           model Phong; terms ambient, diffuse, specular, specular power onto
//                       PhongParams {ambient, diffuse, specular, power} one to one
//   r.gradient_opacity  enabled with these points (x, a) -> GradientOpacityPoint; a function that
//                       is 1 everywhere (Slicer's usual "0 1 255 1") multiplies by 1 and leaves
//                       the feature off (off it costs nothing and changes no pixel)
//   r.blend             the blend mode
// Parts r leaves unset leave the spec's features as they are.
void apply_tf_rendering(const TfRendering& r, FrameSpec& spec,
                        const TfRenderingOverrides& given = {});

// ---- Validation ---------------------------------------------------------------------------------
// The error of validate() is FrameError (lacuna/error.h): its field() names the FrameSpec field.
// Throws FrameError for the first field out of range or not taken by the renderer
// (capabilities()). Needs no volume: a front end calls it before loading anything.
void validate(const FrameSpec& spec);

}  // namespace lacuna
