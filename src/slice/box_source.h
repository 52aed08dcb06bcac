// The object-order seam: what the slice renderer asks of a partition of the volume.
//
// A box source covers every cell that may be visible under the current transfer function with
// pairwise disjoint boxes of cells (CellBox: cells [lo, hi), i.e. the index-space box [lo, hi]),
// and hands them out in visibility order (front to back) for a view. Boxes it leaves out hold
// only cells whose TF opacity is exactly zero everywhere (conservative for trilinear
// interpolation, as for the skipping structures of src/accel/), so the slicer that renders the
// boxes equals the slicer that renders the whole volume ('Basic') byte for byte.
//
// Sources: the whole volume (one box), the growing-boxes partition ordered by its orthogonal BSP
// tree (--accel boxes, growing-boxes paper Sections 3.1-3.2), the kd-tree subvolume list
// (--accel kdtree, kd-tree paper Section 2.2).
#pragma once
#include <vector>

#include "accel/region.h"
#include "lacuna/math.h"
#include "lacuna/transfer_function.h"

namespace lacuna {

class BoxSource {
  public:
    virtual ~BoxSource() = default;
    // Per-TF work (which boxes are skipped); must be called before the first query.
    virtual void set_transfer_function(const TransferLut& lut) = 0;
    // Visible boxes, front to back, for a perspective eye in index space (voxel coordinates)...
    virtual std::vector<CellBox> boxes_front_to_back(Vec3f eye_in_index_space) const = 0;
    // ...and for parallel rays travelling along `dir` (index space; orthographic views).
    virtual std::vector<CellBox> boxes_front_to_back_along(Vec3f dir_in_index_space) const = 0;
    // Short name for reports ("volume", "boxes", "kdtree").
    virtual const char* name() const = 0;
};

}  // namespace lacuna
