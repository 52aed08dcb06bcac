// Per-cell LUT-entry ranges, computed block by block: the TF-independent raw material of every
// skipping structure.
//
// A trilinear sample in cell (i,j,k) lies between the min and max of the cell's 8 corner voxels
// (i..i+1, j..j+1, k..k+1), and ValueToLut is monotone, so it reads a LUT entry in
// [map(min corner), map(max corner)]. Corner values are widened before mapping (relative to the
// largest magnitude of the data and visualization ranges): float trilinear arithmetic can
// exceed its corners by a few ulps of the cell's largest corner.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

// Cell ranges of one block of cells [c0, c0 + n) (n <= edge on each axis; clipped at the grid
// edge). lo/hi hold n[0]*n[1]*n[2] entries, x fastest.
struct BlockCells {
    int block[3];  // block coordinates
    int c0[3];     // first cell
    int n[3];      // cells per axis in this block
    const uint16_t* lo;
    const uint16_t* hi;
};

// Calls fn for every block of edge `edge` cells, in parallel over z-slabs of blocks. fn must be
// thread-safe for distinct blocks.
void for_each_block_cells(const Volume& v, ValueToLut map, int edge, int threads,
                          const std::function<void(const BlockCells&)>& fn);

// One row of cells: cells (0..n-1, j, k), their LUT-entry ranges in lo[i], hi[i].
struct CellRow {
    int j, k, n;
    const uint16_t* lo;
    const uint16_t* hi;
};

// Calls fn for every row of cells, streaming plane by plane (each voxel plane is reduced once
// and shared by the two cell layers it bounds). Rows come in slabs of `slab` cell layers in z;
// one slab is handled by one thread, in order of j then k, so a structure whose blocks are
// `slab` cells deep can accumulate into them without locks. The fast path for builds.
void for_each_cell_row(const Volume& v, ValueToLut map, int slab, int threads,
                       const std::function<void(const CellRow&)>& fn);

// One row of cells in chunks of `chunk` cells (an octree's leaves): per chunk the union of its
// cells' LUT-entry ranges, and each cell's own range only on demand. Integer voxels reduce raw
// values and map just each chunk's extremes (monotone map: same answer as mapping every cell),
// so sparse data costs two table lookups per chunk instead of two per cell.
struct CellChunkRow {
    int j, k, n, chunk;
    const uint16_t* chunk_lo;  // (n + chunk - 1) / chunk entries
    const uint16_t* chunk_hi;
    // Ranges of cells [i0, i1) (at most `chunk` of them) into lo[0 .. i1 - i0), hi[...].
    void cells(int i0, int i1, uint16_t* lo, uint16_t* hi) const { map(ctx, i0, i1, lo, hi); }
    void (*map)(const void* ctx, int i0, int i1, uint16_t* lo, uint16_t* hi);
    const void* ctx;
};

// for_each_cell_row with chunked rows: slabs of `chunk` cell layers, rows in (k, j) order per
// slab and thread. The fast path for octree builds.
void for_each_cell_chunk_row(const Volume& v, ValueToLut map, int chunk, int threads,
                             const std::function<void(const CellChunkRow&)>& fn);

// Per brick of `edge` cells the union of the LUT-entry ranges of the brick's cells and of a
// one-cell apron around it: cells [edge*b - 1, edge*b + edge] on each axis, clipped to the grid
// (voxels [edge*b - 1, edge*b + edge + 1]). The apron is what lets a traversal in float attribute
// a sample to a brick without margins: a sample position within one voxel of the brick's box has
// its cell among these. lo/hi get nb[0]*nb[1]*nb[2] entries, x fastest, nb = ceil(cells/edge).
void apron_brick_ranges(const Volume& v, ValueToLut map, int edge, int threads,
                        std::vector<uint16_t>& lo, std::vector<uint16_t>& hi);

// The visible-cell mask of one TF: bit o of `mask` (32-bit words, bit o & 31 of word o >> 5) is
// set iff the cell whose first corner is voxel offset o = i + j*dx + k*dx*dy may read a visible
// LUT entry: its corner range, widened as every range here is, holds an entry e with
// next_visible[e] <= hi (next_visible[e]: the first visible entry at or after e). Per brick of
// `edge` cells, brick_state(bx, by, bz) says 0: no cell visible (bits stay clear), 2: every cell
// visible (bits set without looking), 1: test each cell. Offsets that are no cell's
// (i = dx - 1, ...) stay clear. mask gets voxels / 32 + 2 words.
void visible_cell_mask(const Volume& v, ValueToLut map, const uint16_t* next_visible, int edge,
                       const std::function<int(int, int, int)>& brick_state, int threads,
                       std::vector<uint32_t>& mask);

// Cells per axis (dims - 1) and blocks per axis for a block edge.
inline void cell_counts(const Volume& v, int cells[3]) {
    const Vec3i d = v.dims();
    cells[0] = d.x - 1, cells[1] = d.y - 1, cells[2] = d.z - 1;
}

// Prefix count of LUT entries with non-zero opacity: visible(lo, hi) in O(1) (min-max paper
// trick).
class OpacityPrefix {
  public:
    void build(const TransferLut& lut) {
        m_prefix.assign(lut.entries.size() + 1, 0);
        for (size_t e = 0; e < lut.entries.size(); ++e)
            m_prefix[e + 1] = m_prefix[e] + (lut.entries[e].a > 0.f ? 1u : 0u);
    }
    bool visible(int lo, int hi) const { return m_prefix[size_t(hi) + 1] != m_prefix[size_t(lo)]; }

  private:
    std::vector<uint32_t> m_prefix;
};

}  // namespace lacuna
