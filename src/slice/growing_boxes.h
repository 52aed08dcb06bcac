// Growing boxes (growing-boxes paper, Section 3.1; Li and Kaufman 2003): a TF-independent
// partition of the cell grid into disjoint axis-aligned boxes of three types,
//   gradient  cells where the data changes (non-zero gradient magnitude), separated first,
//   uniform   boxes whose voxels vary in a small range (spread <= 32 of 256), at least
//             `min_uniform` cells on every axis,
//   other     whatever is left (gaps the uniform boxes' minimum size could not fill),
// and, per transfer function, which boxes are empty (BoxClassifier).
//
// Coordinates are cells: cell (i,j,k) spans voxels i..i+1, ...; the box [lo, hi) of cells is the
// index-space box [lo, hi] and its samples read voxels lo..hi.
//
// Where the paper is silent, lacuna chooses (docs/growing-boxes.md):
//   - gradient cell: one of its 8 corner voxels has a central-difference gradient magnitude
//     above `gradient` x full scale per voxel (full scale: 256 for uint8, the visualization
//     range otherwise). "Non-zero" in the paper is after 8-bit quantisation; real scans are noisy,
//     so the threshold is explicit.
//   - the minimum box size is built in: growth runs on a grid of blocks of min_uniform cells per
//     axis (the last block of an axis takes the remainder), so no box is thinner than
//     min(min_uniform, cells) and no one-cell slivers are left between boxes.
//   - growth: in three phases (gradient, uniform, other) a box starts at the first uncovered seed
//     block in x-fastest order and extends its six faces round robin by one block layer at a
//     time; a face stops for good when its next layer is outside the grid, touches a covered
//     block, or would break the box's cost rule:
//       gradient  cost = non-gradient cells inside; kept <= gradient_waste x volume, and every
//                 added layer must hold a gradient block (a block that meets this rule alone;
//                 such blocks are the seeds),
//       uniform   spread (max - min of the voxels lo..hi) <= the spread limit (a hard bound);
//                 seeds are the uniform blocks left after phase 1,
//       other     cost = volume x spread / full scale (cells); kept <= other_cost; seeds are
//                 the blocks left after phase 2.
//   - the type of a box (after BSP splits and merges) is redetermined by type_of(): gradient
//     if it meets the gradient rule, else uniform if its spread <= the limit, else other. For
//     grown boxes this is the phase that grew them.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "accel/region.h"
#include "accel/summed_volume_table.h"  // box_volume
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

enum class BoxType : uint8_t { Uniform, Gradient, Other };
std::string to_string(BoxType t);  // "uniform", "gradient", "other"

// Typed options of the partition, the BSP merge and the source (`lacuna partition --method
// boxes` and `--accel boxes` fill them).
struct BoxesOptions {
    float spread = 32.f;          // uniform: value spread in 256ths of the full scale (paper: 32)
    int min_uniform = 4;          // uniform: smallest extent in cells on every axis
    float gradient = 0.1f;        // gradient cell: |grad| > gradient x full scale per voxel
    float gradient_waste = 0.5f;  // gradient box: non-gradient cells <= this x volume
    float other_cost = 512.f;     // other box: volume x spread / full scale <= this (cells)
    int thin = 2;                 // merge rule 3: a box with an extent < thin cells is thin
    bool merge = true;            // bottom-up merging of the BSP tree (Section 3.2)
    // Per TF (lacuna's addition, docs/growing-boxes.md): a BSP subtree whose room is at most this
    // fraction empty cells is rendered as one box (its room) instead of leaf by leaf; fewer,
    // larger boxes amortise the per-box polygon set-up. Exact for any value (the image is the
    // Basic image); 0 joins only subtrees without an empty leaf; negative: off.
    float coalesce = 0.25f;
    // ... and only while its room is at most this long on every axis, in world units (mm; cells
    // times spacing): boxes stay fine enough for occlusion culling and clipping, and about as
    // large on screen whatever the voxel size.
    float coalesce_edge = 64.f;
    int threads = 0;  // 0 = all
};
// Throws lacuna::FrameError naming the field ("structure.spread", ...) for a bad value.
void validate(const BoxesOptions& o);
std::string to_string(const BoxesOptions& o);

// One box and what the type rules need. Layout (48 bytes): the cell box, the min and max voxel
// value of voxels lo..hi (native values as float), the number of gradient cells inside, the type.
struct BoxInfo {
    CellBox box;
    float vmin, vmax;
    uint64_t gradient_cells;
    BoxType type;
};
static_assert(sizeof(BoxInfo) == 48);

std::string to_string(const CellBox& b);

// TF-independent facts of a volume the growth and the merge rules query: voxel values and the
// gradient cells (one byte per cell, 1 = gradient cell).
class BoxMeasure {
  public:
    BoxMeasure(const Volume& v, const BoxesOptions& o);
    const Volume& volume() const { return m_volume; }
    const int* cells() const { return m_cells; }
    float full_scale() const { return m_full; }
    float spread_limit() const { return m_limit; }  // value units
    const BoxesOptions& options() const { return m_opts; }
    bool gradient_cell(int i, int j, int k) const {
        return m_grad[(size_t(k) * size_t(m_cells[1]) + size_t(j)) * size_t(m_cells[0]) +
                      size_t(i)] != 0;
    }
    uint64_t gradient_cell_count() const { return m_gradient_total; }
    // Scans the box: value range of voxels lo..hi, gradient cells; type by type_of().
    BoxInfo measure(const CellBox& b) const;
    // The union of two boxes that share a face and form a box (`merged`): no scan needed.
    BoxInfo merge(const BoxInfo& a, const BoxInfo& b, const CellBox& merged) const;
    BoxType type_of(const BoxInfo& i) const;
    bool uniform(float vmin, float vmax) const { return vmax - vmin <= m_limit; }
    double seconds() const { return m_seconds; }  // time of the gradient pass

  private:
    const Volume& m_volume;
    BoxesOptions m_opts;
    int m_cells[3];
    float m_full = 1, m_limit = 0;
    std::vector<uint8_t> m_grad;
    uint64_t m_gradient_total = 0;
    double m_seconds = 0;
};

// Section 3.1: grows gradient boxes, then uniform boxes, then other boxes, until every cell is
// covered exactly once. Boxes come in growth order.
std::vector<BoxInfo> grow_boxes(const BoxMeasure& m);

// Per transfer function, which boxes are empty. Built once per box list and value->LUT mapping:
// every box keeps the exact union of the LUT-entry ranges of its cells (for_each_cell_row, the
// ranges every skipping structure uses). The slicer's ownership is half-open (the box [lo, hi)
// of cells owns samples lo <= p < hi; the sampler clamps the volume's last voxel to the last
// cell), so every sample a box takes reads one of the box's own cells.
// Per TF a box is empty exactly when the TF opacity is zero on every entry of that union: the
// same answer as asking each of those cells, in O(intervals) with the opacity prefix count.
class BoxClassifier {
  public:
    // `vis` and `lut_size` define the value->LUT mapping (TransferLut::map()).
    void build(const Volume& v, ValueRange vis, int lut_size, const std::vector<CellBox>& boxes,
               int threads);
    // empty[b] = 1 when box b is invisible under `lut` (which must use the build's mapping).
    void classify(const TransferLut& lut, std::vector<uint8_t>& empty) const;
    ValueToLut map() const { return m_map; }
    bool same_map(const TransferLut& lut) const;
    size_t boxes() const { return m_offsets.empty() ? 0 : m_offsets.size() - 1; }
    size_t intervals() const { return m_lo.size(); }
    size_t bytes() const { return m_offsets.capacity() * 4 + m_lo.capacity() * 4; }
    // Box b's entry intervals [lo, hi], sorted, disjoint and not adjacent (tests).
    std::vector<std::pair<int, int>> intervals_of(size_t b) const;
    double seconds() const { return m_seconds; }

  private:
    ValueToLut m_map;
    ValueRange m_vis{};
    int m_size = 0;
    std::vector<uint32_t> m_offsets;  // box b's intervals: [m_offsets[b], m_offsets[b+1])
    std::vector<uint16_t> m_lo, m_hi;
    double m_seconds = 0;
};

}  // namespace lacuna
