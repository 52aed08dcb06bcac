// --accel kdtree: the kd-tree paper's empty-space partition as a skipping structure.
//
// Every TF change reruns the paper's four steps over the cells (kdtree_partition.h): classify
// each cell by the TF (non-empty when some LUT entry between the map of its 8 corners' min and
// max has non-zero opacity), build the summed-volume table in place, build the kd-tree, collect
// the subvolume list (every leaf, or at most kd_max_boxes boxes). The ray marcher then asks
// region(cell): the answer descends the tree (at most kd_max_depth + 1 nodes) to the list box that
// holds the cell (occupied, marched through) or to a slab of removed empty space (skipped). This
// is the paper's "front-to-back traversal of the non-empty leaves" seen from one ray: the cursor
// meets the list boxes in ray order. Exact: empty answers hold only cells classified empty.
//
// The same boxes, front to back for a view, are the object-order face for the slicer
// (boxes_in_visibility_order). Threshold classification (the paper's own mode) never feeds this
// structure: it would say nothing about the TF, so make_accel refuses kd_threshold.
#pragma once
#include <vector>

#include "accel/cursor.h"
#include "accel/kdtree_partition.h"
#include "lacuna/accel.h"

namespace lacuna {

class KdTree final : public Accel {
  public:
    // Throws lacuna::Error for invalid kd-tree options or a threshold.
    KdTree(const Volume& v, const AccelOptions& o);
    // Steps 1-4 of the paper for the new TF; stats().tf_update_seconds is their total and
    // step_timings() splits it.
    void set_transfer_function(const TransferLut& lut) override;

    const int* cells() const { return m_part.cells(); }
    Region region(const int cell[3], int&) const { return m_part.region(cell); }
    using Cursor = RegionCursor<KdTree>;

    // The subvolume list front to back for an eye in index space (perspective views) or for
    // parallel rays along `dir` (index space; orthographic views). Boxes are in cells [lo, hi),
    // i.e. voxels lo..hi.
    std::vector<CellBox> boxes_in_visibility_order(Vec3f eye_in_index_space) const {
        return m_part.boxes_in_visibility_order(eye_in_index_space);
    }
    std::vector<CellBox> boxes_in_visibility_order_along(Vec3f dir_in_index_space) const {
        return m_part.boxes_in_visibility_order_along(dir_in_index_space);
    }
    const KdPartition& partition() const { return m_part; }
    const KdTimings& step_timings() const { return m_part.timings(); }

  private:
    const Volume& m_volume;
    KdSettings m_settings;
    KdPartition m_part;
};

}  // namespace lacuna
