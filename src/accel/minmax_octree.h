// --accel minmax: the min-max octree. Each node stores the LUT-entry range [lo, hi] of all the
// cells it covers (TF-independent); a node is empty when the TF has zero opacity on every entry
// of its range, answered in O(1) by a prefix count over the LUT.
//
// --accel minmax-interval is the same tree with the test the bitfield paper's min-max octree
// uses: the TF is reduced to the one interval [first, last] of entries with non-zero opacity,
// and a node is empty when its range misses that interval. An opacity gap inside the interval
// is invisible to that test, which is what the paper's Table 1 shows on its gap TFs. (The
// prefix count sees gaps exactly: on the same tree it skips at least what bitfield skips; see
// docs/benchmarks.md "Bitfield vs minmax on gaps".)
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

    // k: AccelKind::MinMax (prefix count) or AccelKind::MinMaxInterval (the paper's interval).
    MinMaxOctree(AccelKind k, const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    Region region(const int cell[3], int& hint) const {
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional, [&](size_t i) {
            const Node nd = m_nodes[i];
            return m_interval ? nd.hi < m_first || nd.lo > m_last : !m_prefix.visible(nd.lo, nd.hi);
        });
    }
    using Cursor = RegionCursor<MinMaxOctree>;
    // Node i of the pyramid (Pyramid::index): its LUT-entry range ({0xffff, 0} if no cells).
    Node node(size_t i) const { return m_nodes[i]; }
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
    bool m_interval = false;
    int m_first = 1 << 30, m_last = -1;  // the TF's visible interval (none: first > last)
};

}  // namespace lacuna
