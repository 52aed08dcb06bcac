// Empty-space skipping structures, selected by `--accel NAME`.
//
// Every structure answers one question (STYLE.md habit 1): for the cell a ray is in, what is the
// largest axis-aligned box of cells around it that is provably invisible under the current
// transfer function ("empty"), or else which box of cells it may stop looking at ("occupied")?
// One generic cursor (src/accel/cursor.h) turns those answers into the stretches of a ray that
// may contain visible samples; the ray marcher samples only there, on the reference lattice.
//
// Adding a structure: see src/session/structure_registry.h (its names, kinds and faces are
// listed there once); it is then in the conformance tests and the benchmarks automatically.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

enum class AccelKind {
    None,            // march every lattice sample of the ray's box interval (the reference)
    MinMax,          // min-max octree; empty when the TF's opacity prefix sum is 0 over [min, max]
    Bitfield,        // the bitfield paper's TF-independent octree (bins of the visualization range)
    Boolean,         // TF-dependent occupancy octree, rebuilt when the TF changes
    Distance,        // Euclidean distance map at 1/4 resolution, rebuilt when the TF changes
    Chebyshev,       // Chebyshev distance map at 1/4 resolution, rebuilt when the TF changes
    KdTree,          // kd-tree empty-space partition (kd-tree paper), rebuilt when the TF changes
    MinMaxInterval,  // the min-max octree as the bitfield paper tests it: empty when [min, max]
                     // misses the TF's one interval [first visible entry, last visible entry]
    Grid,            // per-TF occupancy grid of bricks (apron-inclusive ranges), two-level 3D DDA
};

std::string to_string(AccelKind k);
// Throws lacuna::FrameError("structure", "unknown 'x'; expected one of: ...").
// "auto" names the default structure (default_accel()).
AccelKind parse_accel(const std::string& name);
// What `--accel auto` (the default of every front end) selects: the fastest exact structure in
// docs/benchmarks.md, the brick grid.
AccelKind default_accel();
std::vector<std::string> accel_names();
// Every kind, None first: what the conformance tests and benchmarks iterate over.
std::vector<AccelKind> all_accel_kinds();

// How the renderers sample the volume between voxels (`--interpolation`).
//   Trilinear  the default: a sample in cell c lies between the min and max of c's 8 corners, so a
//              structure may only skip a cell whose whole corner *range* of LUT entries is
//              transparent (neighbouring cells share corners, so value sets never have holes).
//   Nearest    a sample at index point p takes the voxel floor(p + 0.5) (per axis, in float,
//              clamped into the box): one of the 8 corners of p's cell. A cell's samples then read
//              only its corner *values*, so a structure built for Nearest may skip a cell whose
//              corner values all map to transparent entries even when values between them are
//              visible: the bitfield paper's sets with holes. A structure built for Trilinear is
//              exact for both; one built for Nearest only for Nearest (the renderers check).
enum class Interpolation { Trilinear, Nearest };
std::string to_string(Interpolation i);
// Throws lacuna::FrameError("sampling.interpolation", ...) for a name other than "trilinear" or
// "nearest".
Interpolation parse_interpolation(const std::string& name);

struct AccelOptions {
    // The sampling the structure must be exact for (see Interpolation); only the bitfield octree
    // builds differently for Nearest, every other structure is exact for both as built.
    Interpolation interpolation = Interpolation::Trilinear;
    int leaf_cells = 8;          // octree leaf edge in cells (2..64, power of two)
    int bitfield_bits = 64;      // bitfield width: 8, 16, 32, 64 or 128
    int initial_level = -1;      // octree level traversal starts at (-1 = the root)
    bool bidirectional = true;   // octree traversal moves up and down (false: top-down only)
    int distance_block = 4;      // distance maps: cells per map voxel (the paper's 1/4 resolution)
    int threads = 0;             // build threads (0 = all)
    int kd_max_boxes = 0;        // kd-tree: M, most subvolumes in the list (0 = every leaf)
    int kd_delta = 0;            // kd-tree: candidate plane spacing in cells (0 = from size)
    float kd_min_volume = 0.1f;  // kd-tree: nodes below this fraction of the grid are leaves
    float kd_min_gain = 0.05f;   // kd-tree: a split must remove this fraction of its node
    int kd_max_depth = 10;       // kd-tree: deepest split level (root = 0)
    std::optional<float> kd_threshold;  // kd-tree: value threshold (`lacuna partition` only)
};

struct AccelStats {
    double build_seconds = 0;      // TF-independent build (on load)
    double tf_update_seconds = 0;  // last TF change to ready-to-render
    double refine_seconds = 0;     // last refine(): the optional finer per-TF level
    size_t bytes = 0;              // memory of the structure
    size_t nodes = 0;              // nodes (octrees) or map voxels (distance maps)
};

// A built structure over one volume. Concrete types live in src/accel/; renderers reach them
// through visit() in src/accel/accel_impl.h, once per frame, never per sample.
class Accel {
  public:
    virtual ~Accel() = default;
    AccelKind kind() const { return m_kind; }
    // Must be called before rendering and whenever the TF changes; frames are correct (and
    // exact) right after it.
    virtual void set_transfer_function(const TransferLut& lut) = 0;
    // Computes the structure's optional finer per-TF level for the current TF (the grid's
    // visible-cell mask, src/accel/brick_grid.h), which frames use from then on until the next
    // TF change. It costs more than a TF change, so a front end calls it after the edit, off the
    // frame's critical path (the CLI before its frame, the viewer after sending one). Never
    // concurrently with a render. A no-op for structures without one.
    virtual void refine() {}
    const AccelStats& stats() const { return m_stats; }
    // The sampling this structure is exact for: Trilinear (then also Nearest) or Nearest only.
    Interpolation interpolation() const { return m_interpolation; }

  protected:
    explicit Accel(AccelKind k) : m_kind(k) {}
    AccelKind m_kind;
    AccelStats m_stats;
    Interpolation m_interpolation = Interpolation::Trilinear;
};

// Builds the structure of kind `k` over `volume` (which must outlive it). For None returns a
// trivial structure. Throws lacuna::Error for invalid options.
std::unique_ptr<Accel> make_accel(AccelKind k, const Volume& volume, const AccelOptions& opts = {});

}  // namespace lacuna
