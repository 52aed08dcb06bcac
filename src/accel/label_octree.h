// The label bitfield octree (segment visibility; the bitfield paper's future work, Section 6):
// per node one bit per label value that a sample inside the node can read, as many 64-bit words
// as the label count needs (128 bits for the 116 AAL regions, 65536 at most).
//
// A sample reads the label of its nearest voxel, one of the 8 corners of its trilinear cell, so
// a cell's label set is the labels of its corners and a leaf of cells [lo, hi) holds the labels
// of the voxels [lo, hi] (one past its block edge). Inner nodes are the OR of their children.
// A node is empty when (node AND visible) == 0, where `visible` has a bit per label that can
// contribute (visible and opacity > 0): toggling a label flips one bit, no rebuild.
//
// In masked mode the node is also empty when the intensity TF is transparent over it, tested
// with a bitfield octree of the intensity volume on the same pyramid: either test alone is
// conservative, so their OR is too.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "accel/bitfield_octree.h"
#include "accel/cursor.h"
#include "accel/octree.h"
#include "lacuna/segments.h"

namespace lacuna {

class LabelOctree {
  public:
    // labels: an integer label map (check_label_volume). intensity: optional, same dims.
    LabelOctree(const Volume& labels, const Volume* intensity, const SegmentOptions& o);
    // Masked mode: the intensity TF.
    void set_transfer_function(const TransferLut& lut);
    // Bit l set: label l can be seen. Missing words count as zero.
    void set_visible(const std::vector<uint64_t>& bits);

    Region region(const int cell[3], int& hint) const {
        return octree_region(m_pyr, cell, hint, m_pyr.levels - 1, true,
                             [&](size_t i) { return empty_node(i); });
    }
    bool empty_node(size_t i) const {
        const uint64_t* w = &m_bits[i * size_t(m_words)];
        uint64_t hit = 0;
        for (int k = 0; k < m_words; ++k) hit |= w[k] & m_visible[size_t(k)];
        return hit == 0 || (m_intensity && m_intensity->empty_node(i));
    }
    const int* cells() const { return m_pyr.cells; }
    using Cursor = RegionCursor<LabelOctree>;

    int words() const { return m_words; }
    size_t bytes() const;
    // The label set of pyramid node i (tests).
    const uint64_t* node_bits(size_t i) const { return &m_bits[i * size_t(m_words)]; }
    const Pyramid& pyramid() const { return m_pyr; }

  private:
    Pyramid m_pyr;
    int m_words = 1;
    std::vector<uint64_t> m_bits;     // node-major, m_words per node
    std::vector<uint64_t> m_visible;  // m_words
    std::unique_ptr<BitfieldOctree> m_intensity;
};

}  // namespace lacuna
