// `lacuna bench kdtree`: the kd-tree paper's measurements (Section 3, Table 1 and the M study of
// Section 2.2) on our data. Per dataset (a mricron template resampled to about n^3, or a
// generated tree volume at n^3) and per list limit M (1, 2, 4, ... and every leaf):
//   - subvolumes, share of the volume and of the empty space removed, share of the boxes'
//     volume that is still empty, and the interior holes (empty cells no empty path connects to
//     the grid boundary: the paper's Section 4 limitation) left inside the boxes;
//   - preprocessing steps 1 (classification), 2 (summed-volume table), 3 (kd-tree) and their
//     total (the paper's Table 1 time), median of `repeats` builds, and the memory;
//   - ray-marching frame time with --accel kdtree at that M versus --accel none, measured in
//     the same run over the same orbit, and whether view 0 is byte-identical to none's.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "accel/kdtree_partition.h"
#include "bench/datasets.h"
#include "bench/orbit.h"
#include "bench/report.h"
#include "bench/stats.h"
#include "lacuna/accel.h"

namespace lacuna::bench {

// The kd bench's names for the datasets ("ch2", "ch2better", "ch2bet", "aal", "tree"); the
// faludi names ("ch2-skin", ...) are accepted too. Throws lacuna::Error naming `where`.
DatasetId parse_kd_dataset(const std::string& name, const std::string& where = "--datasets");
std::string kd_dataset_name(DatasetId id);
std::vector<DatasetId> default_kd_datasets();  // ch2, ch2better, ch2bet, aal, tree

struct KdBenchOptions {
    std::vector<DatasetId> datasets = default_kd_datasets();
    std::vector<int> sizes = {256, 512};  // each dataset at n^3 (resampled or generated)
    std::vector<int> max_boxes = {1, 2, 4, 8, 16, 32, 0};  // 0 = every leaf
    OrbitSpec orbit{4, 256, 20.f};                         // views, image size, elevation
    float step = 0.5f;                                     // RenderOptions::step
    float ert = 0.99f;                                     // RenderOptions::ert (>= 1: off)
    int repeats = 5;       // preprocessing builds (medians reported)
    int threads = 0;       // build and render threads (0 = all)
    AccelOptions accel;    // kd settings (kd_max_boxes is overwritten)
    DatasetSource source;  // templates folder, tree seed
};

// Per-cell classes of the TF classification: 0 empty and connected to the grid boundary through
// empty cells (6-connectivity; removable by some box partition), 1 non-empty, 2 an interior hole.
struct HoleMap {
    int cells[3] = {0, 0, 0};
    std::vector<uint8_t> cls;  // x fastest
    uint64_t non_empty = 0, holes = 0;
    // Hole cells inside `box`.
    uint64_t holes_in(const CellBox& box) const;
};
HoleMap find_holes(const Volume& v, const TransferLut& lut, int threads);

struct KdListResult {
    int max_boxes = 0;  // M (0 = every leaf)
    int boxes = 0;      // subvolumes in the list
    uint64_t listed_cells = 0;
    double removed_percent = 0;         // of the volume
    double removed_empty_percent = 0;   // of the empty cells
    double empty_in_boxes_percent = 0;  // of the boxes' volume: empty cells the boxes still hold
    double holes_kept_percent = 0;      // of the interior-hole cells: inside the boxes
    double list_ms = 0;                 // step 4
    double build_ms = 0;                // KdTree steps 1-4 with this M (rendering structure)
    Summary frame_ms;
    uint64_t samples = 0, rays = 0;
    double speedup = 0;  // none's mean frame / this mean frame
    bool exact = false;  // view 0 bytes == none's
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};

struct KdDatasetResult {
    std::string name;         // "ch2bet 256³"
    std::string description;  // source, resampling, TF
    int size = 0;             // the n of n^3
    std::string tf_name;
    Vec3i dims{0, 0, 0};
    VoxelType type = VoxelType::UInt8;
    uint64_t cells = 0, non_empty = 0, holes = 0;
    int nodes = 0, leaves = 0, depth = 0, delta = 0;
    double prepare_s = 0;               // load/resample/generate time
    KdTimings median;                   // per-step medians (seconds)
    double preprocess_median_ms = 0;    // median of the per-build totals of steps 1-3
    std::vector<double> preprocess_ms;  // every build's steps 1-3
    size_t table_bytes = 0, tree_bytes = 0, volume_bytes = 0;
    Summary none_ms;
    uint64_t none_samples = 0, none_rays = 0;
    std::vector<KdListResult> lists;
    double empty_percent() const {
        return cells ? 100.0 * double(cells - non_empty) / double(cells) : 0;
    }
};

struct KdBenchReport {
    KdBenchOptions options;
    std::vector<KdDatasetResult> datasets;
    std::vector<std::string> exactness_failures() const;
};

using KdLogFn = std::function<void(const std::string&)>;
using KdPartialFn = std::function<void(const KdBenchReport&)>;

// Runs one prepared dataset (tests call this on small generated volumes).
KdDatasetResult run_kd_dataset(const BenchDataset& d, int size, const KdBenchOptions& o,
                               const KdLogFn& log = {});
// Loads, resamples / generates and runs every dataset x size. Throws lacuna::Error for missing
// files. `partial` is called after each dataset with the report so far.
KdBenchReport run_kd_bench(const KdBenchOptions& o, const KdLogFn& log = {},
                           const KdPartialFn& partial = {});

std::string kd_bench_markdown(const KdBenchReport& r, const RunInfo& info);
std::string kd_bench_csv(const KdBenchReport& r);

}  // namespace lacuna::bench
