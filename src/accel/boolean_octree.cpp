#include "accel/boolean_octree.h"

#include <chrono>

namespace lacuna {

BooleanOctree::BooleanOctree(const Volume& v, const AccelOptions& o)
    : OctreeBase(AccelKind::Boolean, v, o) {
    // Nothing is TF-independent: the tree is built on the first set_transfer_function().
    m_occupied.assign(m_pyr.node_count(), 1);
    m_stats.nodes = m_occupied.size();
    m_stats.bytes = m_occupied.size();
}

void BooleanOctree::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    needs_rebuild(lut);  // adopts the LUT's value mapping; the rebuild below happens anyway
    OpacityPrefix prefix;
    prefix.build(lut);
    std::fill(m_occupied.begin(), m_occupied.end(), 0);
    for_each_block_cells(m_volume, m_map, 1 << m_pyr.leaf_log2, m_opts.threads, [&](const BlockCells& b) {
        const size_t n = size_t(b.n[0]) * b.n[1] * b.n[2];
        uint8_t occ = 0;
        for (size_t c = 0; c < n && !occ; ++c) occ = prefix.visible(b.lo[c], b.hi[c]);
        m_occupied[m_pyr.index(0, b.block[0], b.block[1], b.block[2])] = occ;
    });
    for (int l = 1; l < m_pyr.levels; ++l)
        for (int z = 0; z < m_pyr.n[l][2]; ++z)
            for (int y = 0; y < m_pyr.n[l][1]; ++y)
                for (int x = 0; x < m_pyr.n[l][0]; ++x) {
                    uint8_t occ = 0;
                    m_pyr.for_children(l, x, y, z, [&](size_t c) { occ |= m_occupied[c]; });
                    m_occupied[m_pyr.index(l, x, y, z)] = occ;
                }
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.build_seconds = m_stats.tf_update_seconds;
}

}  // namespace lacuna
