// `lacuna bench faludi --sweep`: the bitfield octree's parameters, as in the paper's Figures 4
// and 6 (Section 4.3). Early ray termination is off, as in both figures.
//   Figure 4:  leaf size {2..64} x bitfield width {8..128}, traversal from the root.
//   Figure 6a: initial level (how many levels below the root traversal starts) with the best
//              leaf size and width of Figure 4.
//   Figure 6b: bidirectional vs top-down traversal at every initial level.
// The recommended defaults are the settings with the lowest geometric mean, over the datasets,
// of (mean frame time / that dataset's best mean frame time).
#pragma once
#include <string>
#include <vector>

#include "bench/datasets.h"
#include "bench/faludi.h"
#include "bench/orbit.h"
#include "bench/report.h"
#include "bench/stats.h"

namespace lacuna::bench {

struct SweepOptions {
    OrbitSpec orbit{12, 512, 20.f};
    std::vector<int> leaves = {2, 4, 8, 16, 32, 64};
    std::vector<int> bits = {8, 16, 32, 64, 128};
    float step = 0.5f;
    int threads = 0;
};

struct SweepPoint {
    std::string dataset;
    int leaf = 8, bits = 64;
    int levels = 1;          // octree levels for this leaf size and volume
    int initial_level = -1;  // AccelOptions::initial_level (-1: the root)
    bool bidirectional = true;
    Summary frame_ms;
    double generation_ms = 0;  // make_accel + first TF (wall)
    uint64_t samples = 0, rays = 0;
    bool exact = false;  // view 0 bytes == none's view 0
    // Levels ignored below the root (the paper's Figure 6 axis): 0 = start at the root.
    int skipped_levels() const { return initial_level < 0 ? 0 : levels - 1 - initial_level; }
    double samples_per_ray() const { return rays ? double(samples) / double(rays) : 0; }
};

struct SweepResult {
    SweepOptions options;
    std::vector<std::string> datasets;
    std::vector<double> none_ms;        // per dataset: none's view-0 frame time (context)
    std::vector<SweepPoint> leaf_bits;  // Figure 4
    std::vector<SweepPoint> levels;     // Figure 6 (both traversals)
    // The recommendation.
    int best_leaf = 8, best_bits = 64, best_skipped_levels = 0;
    bool best_bidirectional = true;
    std::vector<std::string> exactness_failures() const;
};

SweepResult run_sweep(const std::vector<BenchDataset>& datasets, const SweepOptions& options,
                      const LogFn& log = {});

std::string sweep_leaf_bits_csv(const SweepResult& r);
std::string sweep_levels_csv(const SweepResult& r);
// The sweep's tables and the recommended defaults. `plots` lists the PNG files written next to
// the markdown ("" entries are skipped), or is empty when gnuplot was not available.
std::string sweep_markdown(const SweepResult& r, const RunInfo& info,
                           const std::vector<std::string>& plots);

}  // namespace lacuna::bench
