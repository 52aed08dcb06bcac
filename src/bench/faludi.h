// `lacuna bench faludi`: the layout of the bitfield paper's Table 1 (Faludi et al. 2021,
// Section 4.4) on our datasets. Rows: dataset x {marching only, + early exit}; columns: every
// skipping structure; per cell the mean and p99 frame time over an orbit, samples per ray, the
// speedup over `none` measured in the same run, and whether view 0 is byte-identical to none's.
// Per row also the ideal speedup (src/render/sample_analysis.h); per structure generation time,
// memory and TF-change time. Every cell renders through a Session (lacuna/session.h), as every
// front end does: FrameSpecs per row and structure, the session builds and syncs the structures.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bench/datasets.h"
#include "bench/orbit.h"
#include "bench/stats.h"
#include "lacuna/accel.h"
#include "lacuna/renderer.h"

namespace lacuna::bench {

using LogFn = std::function<void(const std::string&)>;

// The paper's shader configurations.
enum class RowMode {
    MarchingOnly,  // early ray termination off (RenderOptions::ert = kNoEarlyTermination)
    EarlyExit,     // early ray termination at FaludiOptions::ert
    Shading,       // + the paper's PBR shading (on-the-fly gradients) with a headlight
    Lighting,      // + a spotlight with shadow rays through the structure (src/bench/faludi.cpp)
};
std::string to_string(RowMode m);  // "Marching only", "+ Early exit", "+ Shading", "+ Lighting"
std::string csv_name(RowMode m);   // "marching_only", "early_exit", "shading", "lighting"
// Parses "marching", "early-exit", "shading", "lighting"; throws lacuna::Error("--rows", ...).
RowMode parse_row_mode(const std::string& name);

struct FaludiOptions {
    OrbitSpec orbit;
    std::vector<AccelKind> accels = all_accel_kinds();  // None is always run, first
    AccelOptions accel;                                 // octree / distance map settings
    std::vector<RowMode> modes = {RowMode::MarchingOnly, RowMode::EarlyExit};
    float step = 0.5f;   // RenderOptions::step
    float ert = 0.99f;   // the "+ early exit" rows
    int threads = 0;     // render and build threads (0 = all)
    int tf_repeats = 3;  // TF changes timed per structure (the median is reported)
    bool ideal = true;   // count visible-cell samples (the ideal speedup)
    // Each structure computes its finer per-TF level after the TF change (Accel::refine), as the
    // CLI's and the viewer's frames do; false times the structures as they are right after an edit.
    bool refine = true;
    float shadow_step = 1.f;  // '+ Lighting': shadow-ray sample distance (smallest spacings)
    // Every row samples this way, every structure is built for it (AccelOptions::interpolation);
    // under Nearest the ideal counts samples whose own voxel is visible.
    Interpolation interpolation = Interpolation::Trilinear;
};

// The render options of a row for a volume with world box `bounds` (the '+ Lighting' spotlight
// is placed relative to it).
RenderOptions row_render_options(const FaludiOptions& o, RowMode m, const Box3f& bounds);

struct CellResult {
    AccelKind kind = AccelKind::None;
    Summary frame_ms;
    uint64_t samples = 0, rays = 0;  // summed over the orbit
    bool exact = false;              // view 0 bytes == none's view 0 bytes
    double speedup = 0;              // none's mean frame time / this mean
    double sample_reduction = 0;     // none's samples / these samples
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};

struct RowResult {
    RowMode mode = RowMode::MarchingOnly;
    float ert = kNoEarlyTermination;
    uint64_t ideal_samples = 0;     // visible-cell samples over the orbit (0: not computed)
    double ideal_seconds = 0;       // time the count took
    std::vector<CellResult> cells;  // none first, then FaludiOptions::accels order
    const CellResult* find(AccelKind k) const;
    // none's samples / visible-cell samples (0 when not computed).
    double ideal_speedup() const;
    // measured time speedup of `k` as a share of the ideal speedup (0 when unknown).
    double share_of_ideal(AccelKind k) const;
};

struct StructureResult {
    AccelKind kind = AccelKind::None;
    double generation_ms = 0;  // wall time of make_accel + the first set_transfer_function
    double build_ms = 0;       // AccelStats::build_seconds after the first TF
    double tf_change_ms = 0;   // median of AccelStats::tf_update_seconds over tf_repeats changes
    double refine_ms = 0;      // AccelStats::refine_seconds (0: not refined, or nothing to refine)
    size_t bytes = 0, nodes = 0;
};

struct DatasetResult {
    std::string name, description, tf_name;
    Vec3i dims{0, 0, 0};
    VoxelType type = VoxelType::UInt8;
    Vec3d spacing{1, 1, 1};
    double visible_cell_fraction = 0;         // share of cells visible under the TF
    std::vector<StructureResult> structures;  // same order as the row cells
    std::vector<RowResult> rows;
    const StructureResult* find(AccelKind k) const;
};

struct FaludiReport {
    FaludiOptions options;
    std::vector<DatasetResult> datasets;
    // "dataset / row / structure" for every cell whose view 0 differs from none's.
    std::vector<std::string> exactness_failures() const;
};

// The structures to run: None first, then `accels` in order, duplicates dropped.
std::vector<AccelKind> bench_columns(const std::vector<AccelKind>& accels);

// Called after each dataset with the report so far (the CLI rewrites its files, so a long run
// that is interrupted keeps the finished datasets).
using PartialFn = std::function<void(const FaludiReport&)>;

// Runs the table. `log` (may be null) gets a line per structure build and per cell.
FaludiReport run_faludi(const std::vector<BenchDataset>& datasets, const FaludiOptions& options,
                        const LogFn& log = {}, const PartialFn& partial = {});

// The targets, evaluated on a report.
enum class TargetStatus { Met, Missed, NotMeasured, Info };
std::string to_string(TargetStatus s);
struct TargetCheck {
    std::string target;    // what was asked
    std::string measured;  // the numbers behind the verdict
    TargetStatus status = TargetStatus::NotMeasured;
};
std::vector<TargetCheck> check_targets(const FaludiReport& report);

}  // namespace lacuna::bench
