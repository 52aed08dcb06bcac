#include "accel/minmax_octree.h"

#include <chrono>

namespace lacuna {

MinMaxOctree::MinMaxOctree(AccelKind k, const Volume& v, const AccelOptions& o)
    : OctreeBase(k, v, o), m_interval(k == AccelKind::MinMaxInterval) {
    build();
}

void MinMaxOctree::build() {
    const auto t0 = std::chrono::steady_clock::now();
    m_nodes.assign(m_pyr.node_count(), Node{0xffff, 0});
    // Leaves: union of their cells' ranges, accumulated row by row.
    const int B = 1 << m_pyr.leaf_log2;
    for_each_cell_chunk_row(m_volume, m_map, B, m_opts.threads, [&](const CellChunkRow& r) {
        Node* leaf = &m_nodes[m_pyr.index(0, 0, r.j >> m_pyr.leaf_log2, r.k >> m_pyr.leaf_log2)];
        for (int q = 0; q * B < r.n; ++q, ++leaf)
            *leaf = {std::min(leaf->lo, r.chunk_lo[q]), std::max(leaf->hi, r.chunk_hi[q])};
    });
    // Inner nodes: union of their children.
    for (int l = 1; l < m_pyr.levels; ++l)
        for (int z = 0; z < m_pyr.n[l][2]; ++z)
            for (int y = 0; y < m_pyr.n[l][1]; ++y)
                for (int x = 0; x < m_pyr.n[l][0]; ++x) {
                    Node nd{0xffff, 0};
                    m_pyr.for_children(l, x, y, z, [&](size_t c) {
                        nd.lo = std::min(nd.lo, m_nodes[c].lo);
                        nd.hi = std::max(nd.hi, m_nodes[c].hi);
                    });
                    m_nodes[m_pyr.index(l, x, y, z)] = nd;
                }
    m_stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.nodes = m_nodes.size();
    m_stats.bytes = m_nodes.size() * sizeof(Node);
}

void MinMaxOctree::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    if (needs_rebuild(lut)) build();
    m_prefix.build(lut);
    m_first = 1 << 30, m_last = -1;
    for (int e = 0; e < lut.size(); ++e)
        if (lut.entries[size_t(e)].a > 0.f) {
            if (m_first > m_last) m_first = e;
            m_last = e;
        }
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lacuna
