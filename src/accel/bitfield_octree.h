// --accel bitfield: the bitfield paper's TF-independent octree (Sections 3.1-3.4).
//
// The visualization range's LUT entries are split into `bits` equal bins (8..128); bin of entry
// e = e * bits / lut_size. A leaf's bitfield has bit b set when one of its cells can produce a
// sample in bin b: a cell whose corner range maps to entries [lo, hi] sets every bin from bin(lo)
// to bin(hi) (a cell with corners in bins 2 and 9 also covers 3..8). Inner nodes are the OR of
// their children. The TF is encoded as a bitfield of the same width: bit b set when any LUT entry
// of bin b has non-zero opacity. A node is empty when (node AND tf) == 0. A TF change only
// recomputes the TF bitfield (O(lut size)); the tree is built once per volume.
//
// Built for Interpolation::Nearest (AccelOptions), a leaf's bitfield is instead the set of bins of
// the voxels its cells touch: sets with holes, exact only for nearest sampling.
//
// Node layout: `words` uint64 per node (1 for <= 64 bits, 2 for 128), bit b in word b/64.
#pragma once
#include <cstdint>
#include <vector>

#include "accel/octree_base.h"

namespace lacuna {

class BitfieldOctree final : public OctreeBase {
  public:
    BitfieldOctree(const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    Region region(const int cell[3], int& hint) const {
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional,
                             [&](size_t i) { return empty_node(i); });
    }
    // Node i of the pyramid (Pyramid::index) is invisible under the current TF.
    bool empty_node(size_t i) const {
        const uint64_t* w = &m_bits[i * size_t(m_words)];
        uint64_t hit = w[0] & m_tf[0];
        if (m_words == 2) hit |= w[1] & m_tf[1];
        return hit == 0;
    }
    using Cursor = RegionCursor<BitfieldOctree>;
    // MIP/MinIP skipping (src/accel/entry_window.h): empty when no cell of the node can produce
    // a sample whose LUT entry lies in [lo, hi], i.e. the node has no bin of bin(lo)..bin(hi).
    Region region_outside(const int cell[3], int& hint, int lo, int hi) const {
        uint64_t mask[2] = {0, 0};
        if (lo <= hi) {
            const int b0 = bin(std::max(lo, 0)), b1 = bin(std::min(hi, m_lut_size - 1));
            for (int w = 0; w < 2; ++w) {
                const int a = std::max(b0 - 64 * w, 0), b = std::min(b1 - 64 * w, 63);
                if (a > b) continue;
                const uint64_t upto = b == 63 ? ~uint64_t(0) : (uint64_t(1) << (b + 1)) - 1;
                mask[w] = upto & ~((uint64_t(1) << a) - 1);
            }
        }
        return octree_region(m_pyr, cell, hint, m_start, m_opts.bidirectional, [&](size_t i) {
            const uint64_t* w = &m_bits[i * size_t(m_words)];
            uint64_t hit = w[0] & mask[0];
            if (m_words == 2) hit |= w[1] & mask[1];
            return hit == 0;
        });
    }
    int bits() const { return m_nbits; }
    // Node i's bitfield (words() uint64, bit b in word b/64) and the bin of a LUT entry (tests).
    const uint64_t* node_bits(size_t i) const { return &m_bits[i * size_t(m_words)]; }
    int words() const { return m_words; }
    int bin_of(int entry) const { return bin(entry); }
    // The TF bitfield (tests, the viewer's overlay).
    const uint64_t* tf_bits() const { return m_tf; }

  private:
    void build();
    void build_range_leaves();
    void build_nearest_leaves();
    int bin(int entry) const { return int(int64_t(entry) * m_nbits / m_lut_size); }
    int m_nbits = 64, m_words = 1;
    std::vector<uint64_t> m_bits;
    uint64_t m_tf[2] = {0, 0};
};

}  // namespace lacuna
