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
    // Per LUT entry its bin; per bin b the mask of bits below b (so bits [b0, b1] of a word are
    // below[b1 + 1] ^ below[b0]), for each word.
    std::vector<uint8_t> bin_of(static_cast<size_t>(m_lut_size));
    for (int e = 0; e < m_lut_size; ++e) bin_of[size_t(e)] = uint8_t(bin(e));
    uint64_t below[2][130];
    for (int w = 0; w < 2; ++w)
        for (int b = 0; b <= 129; ++b) below[w][b] = b <= 64 * w ? 0 : range_mask(64 * w, b - 1, w);
    const int B = 1 << m_pyr.leaf_log2;
    for_each_cell_chunk_row(m_volume, m_map, B, m_opts.threads, [&](const CellChunkRow& r) {
        uint64_t* leaf =
            &m_bits[m_pyr.index(0, 0, r.j >> m_pyr.leaf_log2, r.k >> m_pyr.leaf_log2) * size_t(W)];
        uint16_t lo[64], hi[64];
        for (int q = 0, i0 = 0; i0 < r.n; ++q, i0 += B, leaf += W) {
            // Common in sparse data: every cell of the chunk in one bin.
            const int c0 = bin_of[r.chunk_lo[q]], c1 = bin_of[r.chunk_hi[q]];
            if (c0 == c1) {
                leaf[c0 >> 6 < W ? c0 >> 6 : 0] |= uint64_t(1) << (c0 & 63);
                continue;
            }
            const int i1 = std::min(r.n, i0 + B);
            r.cells(i0, i1, lo, hi);
            for (int w = 0; w < W; ++w) {
                uint64_t acc = leaf[w];
                for (int i = 0; i < i1 - i0; ++i) {
                    const int b0 = bin_of[lo[i]], b1 = bin_of[hi[i]];
                    acc |= below[w][b1 + 1] ^ below[w][b0];
                }
                leaf[w] = acc;
            }
        }
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
