// --accel boolean: a TF-dependent occupancy octree. A leaf is occupied when any of its cells
// can produce a sample with non-zero opacity under the current TF (decided per cell from the
// cell's corner range, so it is as tight as a per-cell test can be); inner nodes are the OR of
// their children. Every TF change rebuilds it from the volume — the cost the bitfield paper's
// TF-independent tree avoids.
//
// Node layout: one byte per node, 1 = occupied.
#pragma once
#include <cstdint>
#include <vector>

#include "accel/octree_base.h"

namespace lacuna {

class BooleanOctree final : public OctreeBase {
  public:
    BooleanOctree(const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    Region region(const int cell[3], int& hint) const {
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional,
                             [&](size_t i) { return m_occupied[i] == 0; });
    }
    using Cursor = RegionCursor<BooleanOctree>;

  private:
    std::vector<uint8_t> m_occupied;
};

}  // namespace lacuna
