// `lacuna partition --method boxes`: the growing boxes and their BSP tree (growing-boxes paper,
// Sections 3.1-3.2) — counts and build times, a JSON list, and a picture like the paper's
// Figure 2 (one slice: grown boxes left, BSP leaves after merging right, coloured by type).
#pragma once
#include <string>

#include "lacuna/math.h"
#include "lacuna/volume.h"
#include "slice/growing_boxes.h"

namespace lacuna::cli {

struct PartitionBoxesArgs {
    std::string volume_path, tf, json, out;
    BoxesOptions options;
    int slice = -1;  // the picture's axial cell layer from the inferior end (-1: the middle)
    int size = 512;  // picture: each panel's longer side is about this many pixels
    float azimuth = 30.f, elevation = 20.f;  // the view whose visibility order the JSON lists
    int repeat = 1;                          // builds; median step times are reported
};

// `file` is loaded (and its --range applied) by the caller. The boxes are built on its voxels in
// RAS order (partition_frame.h), so one anatomy gives one set of boxes whatever the voxel order.
void run_partition_boxes(const PartitionBoxesArgs& a, const Volume& file);

}  // namespace lacuna::cli
