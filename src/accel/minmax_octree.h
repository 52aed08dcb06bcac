// --accel minmax: the min-max octree. Each node stores the LUT-entry range [lo, hi] of all the
// cells it covers (TF-independent); a node is empty when the TF has zero opacity on every entry
// of its range, answered in O(1) by a prefix count over the LUT.
//
// Node layout: 4 bytes, lo then hi, LUT entries (uint16).
#pragma once
#include <cstdint>
#include <vector>

#include "accel/octree_base.h"

namespace lacuna {

class MinMaxOctree final : public OctreeBase {
public:
    struct Node {
        uint16_t lo, hi;
    };
    static_assert(sizeof(Node) == 4);

    MinMaxOctree(const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    Region region(const int cell[3], int& hint) const {
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional, [&](size_t i) {
            return !m_prefix.visible(m_nodes[i].lo, m_nodes[i].hi);
        });
    }
    using Cursor = RegionCursor<MinMaxOctree>;
    // Region maximum/minimum query for MIP and MinIP skipping (src/accel/entry_window.h): empty
    // when no cell of the node can produce a sample whose LUT entry lies in [lo, hi].
    Region region_outside(const int cell[3], int& hint, int lo, int hi) const {
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional, [&](size_t i) {
            return int(m_nodes[i].hi) < lo || int(m_nodes[i].lo) > hi;
        });
    }

private:
    void build();
    std::vector<Node> m_nodes;
    OpacityPrefix m_prefix;
};

}  // namespace lacuna
