#include "accel/label_octree.h"

#include <algorithm>

#include "accel/cell_ranges.h"
#include "core/parallel.h"

namespace lacuna {

namespace {

// ORs the label bits of voxels [lo, hi] (inclusive, per axis) into `out`.
template <class T>
void collect(const T* data, Vec3i d, const int lo[3], const int hi[3], uint64_t* out) {
    for (int k = lo[2]; k <= hi[2]; ++k)
        for (int j = lo[1]; j <= hi[1]; ++j) {
            const T* row = data + (size_t(k) * size_t(d.y) + size_t(j)) * size_t(d.x);
            T prev = row[lo[0]];
            out[size_t(prev) >> 6] |= uint64_t(1) << (size_t(prev) & 63);
            for (int i = lo[0] + 1; i <= hi[0]; ++i) {
                const T l = row[i];
                if (l == prev) continue;  // labels come in runs
                prev = l;
                out[size_t(l) >> 6] |= uint64_t(1) << (size_t(l) & 63);
            }
        }
}

}  // namespace

LabelOctree::LabelOctree(const Volume& labels, const Volume* intensity, const SegmentOptions& o) {
    check_label_volume(labels, intensity, "labels");
    int c[3];
    cell_counts(labels, c);
    m_pyr.init(c, o.leaf_cells);
    m_words = std::max(1, (label_count(labels) + 63) / 64);
    m_bits.assign(m_pyr.node_count() * size_t(m_words), 0);
    m_visible.assign(size_t(m_words), 0);
    const int W = m_words;
    const Vec3i d = labels.dims();
    // Leaves, in parallel over z-slabs of leaves (each leaf written by one thread).
    const int nz = m_pyr.n[0][2];
    parallel_for(size_t(nz), 0, [&](size_t z0, size_t z1) {
        for (int z = int(z0); z < int(z1); ++z)
            for (int y = 0; y < m_pyr.n[0][1]; ++y)
                for (int x = 0; x < m_pyr.n[0][0]; ++x) {
                    const CellBox b = m_pyr.box(0, x, y, z);
                    uint64_t* out = &m_bits[m_pyr.index(0, x, y, z) * size_t(W)];
                    // Cells [lo, hi) read voxels [lo, hi].
                    visit_voxels(labels, [&](const auto* data) {
                        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
                        if constexpr (!std::is_same_v<T, float>) collect(data, d, b.lo, b.hi, out);
                    });
                }
    });
    // Inner nodes: OR of the children.
    for (int l = 1; l < m_pyr.levels; ++l)
        for (int z = 0; z < m_pyr.n[l][2]; ++z)
            for (int y = 0; y < m_pyr.n[l][1]; ++y)
                for (int x = 0; x < m_pyr.n[l][0]; ++x) {
                    uint64_t* out = &m_bits[m_pyr.index(l, x, y, z) * size_t(W)];
                    m_pyr.for_children(l, x, y, z, [&](size_t child) {
                        const uint64_t* in = &m_bits[child * size_t(W)];
                        for (int w = 0; w < W; ++w) out[w] |= in[w];
                    });
                }
    if (intensity) {
        AccelOptions ao;
        ao.leaf_cells = o.leaf_cells;
        ao.bitfield_bits = o.bitfield_bits;
        m_intensity = std::make_unique<BitfieldOctree>(*intensity, ao);
    }
}

void LabelOctree::set_transfer_function(const TransferLut& lut) {
    if (m_intensity) m_intensity->set_transfer_function(lut);
}

void LabelOctree::set_visible(const std::vector<uint64_t>& bits) {
    for (size_t w = 0; w < m_visible.size(); ++w) m_visible[w] = w < bits.size() ? bits[w] : 0;
}

size_t LabelOctree::bytes() const {
    return m_bits.size() * sizeof(uint64_t) + (m_intensity ? m_intensity->stats().bytes : 0);
}

}  // namespace lacuna
