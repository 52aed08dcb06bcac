// The volume split into one brick per rank by a kd-tree (docs/distributed.md, "Decomposition").
//
// Cells, not voxels, are split: the whole grid has dims - 1 cells per axis, a split is a cell
// plane p (a node's cells [lo, p) go low, [p, hi) high), and rank r owns the cell box of its leaf.
// In index space that leaf owns the half-open box [lo, hi) of positions (BrickOwnership,
// lacuna/renderer.h), with -inf / +inf on the faces that are the grid's own, so the owned boxes
// partition space and every lattice sample has exactly one owner (render/ownership.h). A rank
// reads the voxels [lo - 1, hi + 1] of its cells, clamped to the grid: [lo, hi] is what its
// owned samples interpolate (hi included: cells [hi - 1, hi) interpolate to voxel hi), and the
// ghost voxels lo - 1 and hi + 1 are what the central differences of the gradients at voxels lo
// and hi read (shading, gradient opacity: src/render/feature_kernel.h), so a brick's gradients
// at every voxel its samples interpolate are the whole volume's, bit for bit.
//
// Balance. Each split puts the fraction of the node's weight that its two subtrees' leaf counts
// ask for on each side, along the node's longest axis: weight = cells (--balance voxels), or
// cells the TF can make visible (--balance visible: the kd-tree paper's summed-volume table,
// src/accel/summed_volume_table.h, gives the count of any box in eight lookups, so each plane is
// found by bisection over the node's slabs).
//
// Shape, for binary-swap compositing (src/dist/composite.h). With P the largest power of two
// <= N and E = N - P, the top log2(P) levels are a complete binary tree over P slots, slot s
// holding rank s; slots s < E split once more into ranks s and P + s. So ranks that differ in
// bit b of their slot are the two subtrees of one node (binary swap's round-b partners), and an
// extra rank P + s is the sibling of rank s (it folds into s before the swap).
//
// Visibility order. The tree is a BSP of planes: for a perspective camera the child on the eye's
// side of a node's plane is in front of the other along every ray from the eye (a ray crosses the
// plane at most once, from the eye's side); for an orthographic camera the side the rays come
// from. So an in-order walk, near child first, lists the ranks front to back for the whole image.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "accel/region.h"
#include "accel/summed_volume_table.h"
#include "lacuna/math.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::dist {

enum class Balance { Voxels, Visible };
std::string to_string(Balance b);

// One node of the tree. Layout: `axis` -1 for a leaf (then `rank` is its rank), else the split
// axis with `plane` the cell plane in whole-grid cells (children[0] holds cells < plane).
struct KdNode {
    CellBox box;    // the node's cells, whole grid, [lo, hi)
    int axis = -1;  // split axis 0..2, -1: leaf
    int plane = 0;  // split cell plane
    int children[2] = {-1, -1};
    int rank = -1;                 // leaves only
    int slot_lo = 0, slot_hi = 0;  // the binary-swap slots [slot_lo, slot_hi) below the node
};

struct Decomposition {
    Vec3i dims{0, 0, 0};          // the whole grid's voxels
    std::vector<KdNode> nodes;    // nodes[0] is the root
    std::vector<CellBox> bricks;  // the cell box of each rank
    int ranks() const { return int(bricks.size()); }
};
std::string to_string(const Decomposition& d);

// Weight of a cell box (a count: cells, visible cells); additive over disjoint boxes.
using CellWeight = std::function<double(const CellBox&)>;

// The kd-tree of `ranks` bricks over the cells of a grid of `dims` voxels. Throws lacuna::Error
// when the grid has fewer cells than ranks along the splits (every brick holds at least one cell
// per axis).
Decomposition decompose(Vec3i dims, int ranks, const CellWeight& weight);
// Balanced on cells.
Decomposition decompose_voxels(Vec3i dims, int ranks);
// Balanced on the cells `lut` can make visible (TF opacity > 0 somewhere in the cell's value
// range); falls back to cells for a node holding no visible cell.
Decomposition decompose_visible(const Volume& v, const TransferLut& lut, int ranks, int threads);
// The same tree when each rank holds only its slab of the volume: the voxels of `cells` (plus
// the ghost layer), boxes that over the ranks partition the grid's cells (the bricks of
// decompose_voxels). A box's weight is the sum over the ranks of its visible cells inside their
// slabs, each counted by the slab's own summed-volume table (SlabCounts, built first: it may
// fail, the sums may not), and `sum` adds them up over the ranks (an allreduce: every rank makes
// the same calls in the same order, since every rank builds the same tree from the same sums).
// For integer voxels the tree is decompose_visible's over the whole volume; for float voxels
// the cells' corner ranges are widened relative to the slab's data range, not the whole's
// (cell_ranges.h), which can move a cell within ulps of a TF edge, and so a plane.
class SlabCounts {
  public:
    // `slab`: the voxels ownership(d, r).offset + [0, brick_voxels(d, r)) of `cells`' brick.
    SlabCounts(const Volume& slab, Vec3i offset, const CellBox& cells, const TransferLut& lut,
               int threads);
    // Visible cells of the whole-grid box `b` inside this slab.
    uint64_t count(const CellBox& b) const;
    size_t bytes() const { return m_t32.bytes() + m_t64.bytes(); }

  private:
    CellBox m_cells;
    Vec3i m_offset;  // the slab's voxel (0, 0, 0) in the whole grid
    bool m_narrow;
    SummedVolumeTable<uint32_t> m_t32;  // when the slab's cells fit 32 bits (the table's rule)
    SummedVolumeTable<uint64_t> m_t64;
};
Decomposition decompose_visible_slabs(Vec3i dims, const SlabCounts& mine, int ranks,
                                      const std::function<uint64_t(uint64_t)>& sum);

// The owned box of `rank` and the voxels it reads: offset = max(brick.lo - 1, 0), up to and
// including min(brick.hi + 1, dims - 1) (the ghost layer above).
BrickOwnership ownership(const Decomposition& d, int rank);
Vec3i brick_voxels(const Decomposition& d, int rank);

// Ranks front to back for a camera whose eye (perspective) or ray direction (orthographic) is
// given in whole-grid index space.
std::vector<int> visibility_order(const Decomposition& d, Vec3f eye, Vec3f dir, bool orthographic);
// Whether child 0 (the low side) of node `n` is in front, for the same camera.
bool low_in_front(const KdNode& n, Vec3f eye, Vec3f dir, bool orthographic);

// Binary swap's shape: P = the largest power of two <= ranks.
int swap_ranks(int ranks);
// The inner node over slots [a, b): for b - a >= 2 the node whose subtrees hold the two halves
// of the range (a node of the complete top), for b - a == 1 (a < E) the node splitting slot a into
// ranks a and P + a. -1 if there is none.
int slot_node(const Decomposition& d, int a, int b);

}  // namespace lacuna::dist
