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
    const int B = 1 << m_pyr.leaf_log2;
    for_each_cell_chunk_row(m_volume, m_map, B, m_opts.threads, [&](const CellChunkRow& r) {
        uint8_t* leaf =
            &m_occupied[m_pyr.index(0, 0, r.j >> m_pyr.leaf_log2, r.k >> m_pyr.leaf_log2)];
        uint16_t lo[64], hi[64];
        for (int q = 0, i0 = 0; i0 < r.n; ++q, i0 += B, ++leaf) {
            // A chunk whose union is invisible has no visible cell; otherwise ask each cell
            // (the union can span an opaque gap no single cell reaches).
            if (*leaf || !prefix.visible(r.chunk_lo[q], r.chunk_hi[q])) continue;
            const int i1 = std::min(r.n, i0 + B);
            r.cells(i0, i1, lo, hi);
            uint8_t occ = 0;
            for (int i = 0; i < i1 - i0 && !occ; ++i) occ = prefix.visible(lo[i], hi[i]);
            *leaf = occ;
        }
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
