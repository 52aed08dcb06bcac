// `lacuna bench li`: the growing-boxes paper's Tables 1 and 2 (Li, Mueller, Kaufman 2003,
// Section 5) on our datasets, with the CPU slice renderer. Per dataset, over one orbit:
//   Basic    the whole volume as one box
//   ESS      the box source's boxes (empty space skipped)
//   ESS+CC   + occlusion culling and clipping (adaptive number of map updates, Section 4.4)
//   ESS+M    + every map update and box test, nothing skipped (the overhead)
//   ESS+C    + culling only
// and the ray marcher (none and the same structure) on the same settings. Reported: mean frame
// times, the share of non-empty voxels culled / clipped, the speedups ESS, CC, ESS+CC measured in
// the same run, the polygon set-up share of the frame, the desired and actual map updates per
// frame (the paper's Figure 6), and whether ESS equals Basic byte for byte.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "bench/datasets.h"
#include "bench/orbit.h"
#include "bench/report.h"
#include "lacuna/accel.h"
#include "slice/growing_boxes.h"

namespace lacuna::bench {

struct LiOptions {
    OrbitSpec orbit{8, 384, 20.f};
    std::string ess = "boxes";  // box source of the ESS columns
    AccelOptions accel;
    BoxesOptions boxes;  // the ESS source "boxes"
    float step = 0.5f;
    float threshold = 0.95f;
    int map_size = 64;
    int initial_updates = 9;  // k of the adaptive window
    int threads = 0;
    bool march = true;       // also time the ray marcher
    int updates_views = 60;  // Figure 6: ESS+CC frames of a longer orbit on the first dataset
                             // (0 = none)
};

struct LiColumn {
    std::string name;  // "Basic", "ESS", ...
    std::vector<double> frame_ms;
    double mean_ms = 0;
    double cpu_ms = 0;               // mean process CPU time per frame (all threads; robust to a
                                     // machine shared with other jobs)
    double setup_fraction = 0;       // mean polygon set-up share of the frame's CPU time
    double setup_wall = 0;           // ... of its wall time (depends on thread scheduling)
    double culled = 0, clipped = 0;  // mean shares of non-empty voxels
    double samples = 0;              // mean composited samples per frame
};

struct LiDataset {
    std::string name, description, tf_name;
    Vec3i dims{0, 0, 0};
    double source_ms = 0;  // building the box source and applying the TF
    // Growing boxes only: the partition (gradient cells, growth, measuring the BSP pieces, the
    // per-box LUT ranges) and the BSP tree (splitting and merging), from BoxesBuildStats.
    double partition_ms = -1, bsp_ms = -1;
    size_t boxes = 0;               // boxes of view 0
    double box_voxels = 0;          // share of the volume's cells inside the boxes
    std::vector<LiColumn> columns;  // Basic, ESS, ESS+CC, ESS+M, ESS+C, march none, march ESS
    bool ess_exact = false;         // ESS view 0 == Basic view 0, byte for byte
    bool map_only_exact = false;    // ESS+M view 0 == ESS view 0
    int max_cc_diff = 0;            // largest 8-bit difference ESS+CC vs ESS over view 0
    std::vector<int> desired_updates, actual_updates;  // ESS+CC, per frame
    const LiColumn* find(const std::string& n) const;
};

// Figure 6 of the paper: desired and actual map updates per frame of an orbit (ESS+CC with the
// adaptive controller), and the share of non-empty voxels skipped per frame.
struct LiUpdates {
    std::string dataset;
    std::vector<int> desired, actual;
    std::vector<double> skipped;
};

struct LiReport {
    LiOptions options;
    std::vector<LiDataset> datasets;
    LiUpdates figure6;  // empty when options.updates_views == 0
};

using LiLog = std::function<void(const std::string&)>;
LiReport run_li(const std::vector<BenchDataset>& datasets, const LiOptions& options,
                const LiLog& log = {});

std::string li_markdown(const LiReport& r, const RunInfo& info);
std::string li_csv(const LiReport& r);          // one line per dataset x column
std::string li_updates_csv(const LiReport& r);  // dataset, frame, desired, actual (Figure 6)
// gnuplot script drawing Figure 6 (desired and actual updates per frame) into png_path.
std::string li_updates_gnuplot(const LiReport& r, const std::string& png_path);

}  // namespace lacuna::bench
