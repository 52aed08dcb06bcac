#include "accel/bitfield_octree.h"

#include <chrono>

#include "core/parallel.h"

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
        throw FrameError("structure.bits",
                         "expected 8, 16, 32, 64 or 128, got " + std::to_string(b));
    m_nbits = b;
    m_words = b > 64 ? 2 : 1;
    m_interpolation = o.interpolation;
    build();
}

// Nearest sampling: a sample in cell c reads one of c's 8 corner voxels, so a leaf's bitfield is
// the set of bins of the voxels its cells touch, voxels [B*x, B*x + B] per axis (clipped), with
// holes: two voxels in bins 2 and 9 set bits 2 and 9 only. Values are mapped as the kernels map
// a nearest sample (ValueToLut of the voxel value itself: no widening, no interpolation).
void BitfieldOctree::build_nearest_leaves() {
    const int W = m_words, L = m_pyr.leaf_log2, B = 1 << L;
    const Vec3i d = m_volume.dims();
    const int* nl = m_pyr.n[0];
    visit_voxels(m_volume, [&](const auto* data) {
        parallel_for(size_t(nl[2]), m_opts.threads, [&](size_t z0, size_t z1) {
            std::vector<int> bins(size_t(d.x));
            for (int lz = int(z0); lz < int(z1); ++lz)
                for (int ly = 0; ly < nl[1]; ++ly) {
                    uint64_t* row = &m_bits[m_pyr.index(0, 0, ly, lz) * size_t(W)];
                    const int k1 = std::min((lz + 1) << L, d.z - 1),
                              j1 = std::min((ly + 1) << L, d.y - 1);
                    for (int k = lz << L; k <= k1; ++k)
                        for (int j = ly << L; j <= j1; ++j) {
                            const auto* v =
                                data + (size_t(k) * size_t(d.y) + size_t(j)) * size_t(d.x);
                            for (int i = 0; i < d.x; ++i) bins[size_t(i)] = bin(m_map(float(v[i])));
                            // Voxel i is a corner of the cells i - 1 and i: of leaf i / B, and
                            // of leaf i / B - 1 when it starts that leaf.
                            for (int i = 0; i < d.x; ++i) {
                                const int b = bins[size_t(i)], lx = std::min(i >> L, nl[0] - 1);
                                const uint64_t bit = uint64_t(1) << (b & 63);
                                row[size_t(lx) * size_t(W) + size_t(b >> 6)] |= bit;
                                if ((i & (B - 1)) == 0 && lx > 0 && (i >> L) == lx)
                                    row[size_t(lx - 1) * size_t(W) + size_t(b >> 6)] |= bit;
                            }
                        }
                }
        });
    });
}

// Trilinear sampling: each cell sets the bins of its whole corner range.
void BitfieldOctree::build_range_leaves() {
    const int W = m_words;
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
}

void BitfieldOctree::build() {
    const auto t0 = std::chrono::steady_clock::now();
    const int W = m_words;
    m_bits.assign(m_pyr.node_count() * size_t(W), 0);
    if (m_interpolation == Interpolation::Nearest)
        build_nearest_leaves();
    else
        build_range_leaves();
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
