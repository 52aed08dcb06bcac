#include "accel/bitfield_octree.h"

#include <chrono>

namespace lacuna {

namespace {
// Bits [b0, b1] of word w (bits 64w .. 64w+63).
uint64_t range_mask(int b0, int b1, int w) {
    const int lo = std::max(b0, 64 * w), hi = std::min(b1, 64 * w + 63);
    if (lo > hi) return 0;
    const int a = lo - 64 * w, b = hi - 64 * w;
    const uint64_t upto_b = b == 63 ? ~uint64_t(0) : ((uint64_t(1) << (b + 1)) - 1);
    return upto_b & ~((uint64_t(1) << a) - 1);
}
}  // namespace

BitfieldOctree::BitfieldOctree(const Volume& v, const AccelOptions& o)
    : OctreeBase(AccelKind::Bitfield, v, o) {
    const int b = o.bitfield_bits;
    if (b != 8 && b != 16 && b != 32 && b != 64 && b != 128)
        throw Error("--bits", "bitfield width", "expected 8, 16, 32, 64 or 128, got " + std::to_string(b));
    m_nbits = b;
    m_words = b > 64 ? 2 : 1;
    build();
}

void BitfieldOctree::build() {
    const auto t0 = std::chrono::steady_clock::now();
    const int W = m_words;
    m_bits.assign(m_pyr.node_count() * size_t(W), 0);
    for_each_block_cells(m_volume, m_map, 1 << m_pyr.leaf_log2, m_opts.threads, [&](const BlockCells& b) {
        const size_t n = size_t(b.n[0]) * b.n[1] * b.n[2];
        uint64_t acc[2] = {0, 0};
        // Consecutive cells often share a range: remember the last one.
        int last_lo = -1, last_hi = -1;
        for (size_t c = 0; c < n; ++c) {
            if (b.lo[c] == last_lo && b.hi[c] == last_hi) continue;
            last_lo = b.lo[c], last_hi = b.hi[c];
            const int b0 = bin(last_lo), b1 = bin(last_hi);
            for (int w = 0; w < W; ++w) acc[w] |= range_mask(b0, b1, w);
        }
        uint64_t* dst = &m_bits[m_pyr.index(0, b.block[0], b.block[1], b.block[2]) * size_t(W)];
        for (int w = 0; w < W; ++w) dst[w] = acc[w];
    });
    for (int l = 1; l < m_pyr.levels; ++l)
        for (int z = 0; z < m_pyr.n[l][2]; ++z)
            for (int y = 0; y < m_pyr.n[l][1]; ++y)
                for (int x = 0; x < m_pyr.n[l][0]; ++x) {
                    uint64_t* dst = &m_bits[m_pyr.index(l, x, y, z) * size_t(W)];
                    m_pyr.for_children(l, x, y, z, [&](size_t c) {
                        for (int w = 0; w < W; ++w) dst[w] |= m_bits[c * size_t(W) + w];
                    });
                }
    m_stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.nodes = m_pyr.node_count();
    m_stats.bytes = m_bits.size() * sizeof(uint64_t);
}

void BitfieldOctree::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    if (needs_rebuild(lut)) build();
    m_tf[0] = m_tf[1] = 0;
    for (int e = 0; e < lut.size(); ++e)
        if (lut.entries[size_t(e)].a > 0.f) {
            const int b = bin(e);
            m_tf[b >> 6] |= uint64_t(1) << (b & 63);
        }
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lacuna
