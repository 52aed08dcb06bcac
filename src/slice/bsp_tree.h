// The orthogonal BSP tree of a box set (growing-boxes paper, Section 3.2): every split plane is
// perpendicular to an axis, so any view's visibility order is one tree traversal.
//
// Input: disjoint boxes of cells that tile a room exactly (the growing boxes tile the grid).
// Splitting (the paper's pseudo-code): a node holds a list of boxes and their bounding box, the
// room. Its split plane is chosen among the faces of its boxes strictly inside the room (with a
// tiling each such face is shared by at least two boxes) to minimise the boxes the plane cuts;
// ties go to the plane that balances the two lists best (largest list smallest), then the lower
// axis, then the lower plane (lacuna's choice; the paper does not say). A cut box becomes two
// child boxes whose parent is the cut box if it was an original grown box, or else the cut box's
// parent (one level of parenthood: no box is both parent and child); the cut box is dropped.
// A node with one box is a leaf, and its box equals its room.
//
// Merging (bottom-up): a node whose two children are leaves becomes a leaf holding their union
// (its room) when the caller's rule says so; two merged children with different parents delete
// those parents (their other children become parentless). Merging repeats up the tree.
//
// Visibility order: at a node split at x_a = p, the side holding the eye (perspective; either
// side when the eye is on the plane) or the side parallel rays enter first (dir_a >= 0: the low
// side) comes first. Any ray crosses each plane at most once, so within any ray the leaves come
// in this order.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "accel/region.h"
#include "lacuna/math.h"

namespace lacuna {

// One box of the tree. Layout (32 bytes): the cell box, then
//   grown   the original grown box this box lies in (index into build()'s input), -1 for a box
//           made by merging,
//   parent  index into build()'s input of the grown box this piece was cut from while that
//           parent is alive; -1 for an original grown box and for parentless boxes.
struct BspBox {
    CellBox box;
    int32_t grown;
    int32_t parent;
};
static_assert(sizeof(BspBox) == 32);

// One node. Layout (40 bytes): the room (cells), the index of the low-side child (the high side
// is low + 1; -1 for a leaf), split axis and plane (index-space plane x_axis = plane: the low
// child holds cells < plane), and for a leaf its box (index into boxes()).
struct BspNode {
    CellBox room;
    int32_t low;
    int16_t axis;
    int16_t pad;
    int32_t plane;
    int32_t box;
    bool is_leaf() const { return low < 0; }
};
static_assert(sizeof(BspNode) == 40);

struct BspStats {
    size_t input = 0;   // boxes given to build()
    size_t cut = 0;     // boxes cut by split planes (each cut adds one box)
    size_t leaves = 0;  // leaves after splitting
    size_t merged = 0;  // merges done
    size_t final_leaves = 0;
    int depth = 0;  // deepest leaf after splitting (root = 0)
    double split_seconds = 0, merge_seconds = 0;
};

class BspTree {
  public:
    // Splits until every leaf holds one box. `boxes` must tile `room` (checked: lacuna::Error
    // if a leaf's box is not its room, i.e. the boxes overlap or leave holes).
    void build(const std::vector<CellBox>& boxes, const CellBox& room);

    // Bottom-up merging. rule(low, high, merged) gets the indices (into boxes()) of two sibling
    // leaves and their union; returning true merges them into a new box, appended at index
    // boxes().size() (so the caller can append its per-box data at that index).
    using MergeRule = std::function<bool(int32_t low, int32_t high, const CellBox& merged)>;
    void merge(const MergeRule& rule);

    // Leaf box indices front to back for an eye (index space), or for parallel rays along dir.
    void order(Vec3f eye, std::vector<int32_t>& out) const { traverse(eye, false, out); }
    void order_along(Vec3f dir, std::vector<int32_t>& out) const { traverse(dir, true, out); }
    // Node indices front to back through a cut of the tree: cut[node] = 0 descends (inner nodes
    // only), 1 emits the node (its room), 2 skips its subtree. For an eye (is_dir false) or
    // parallel rays along a direction (is_dir true).
    enum Cut : uint8_t { kDescend = 0, kEmit = 1, kSkip = 2 };
    void order_cut(Vec3f key, bool is_dir, const std::vector<uint8_t>& cut,
                   std::vector<int32_t>& out) const;

    const std::vector<BspNode>& nodes() const { return m_nodes; }
    const std::vector<BspBox>& boxes() const { return m_boxes; }
    // The box indices of the leaves, in tree order (low side first).
    std::vector<int32_t> leaves() const;
    // The parent a leaf box has now (-1 once its parent was deleted by a merge).
    int32_t parent_of(int32_t box) const;
    // Sub-volumes the paper would make textures for: leaf boxes without a parent plus the live
    // parents of the others.
    size_t sub_volumes() const;
    const BspStats& stats() const { return m_stats; }
    size_t bytes() const {
        return m_nodes.capacity() * sizeof(BspNode) + m_boxes.capacity() * sizeof(BspBox) +
               m_parent_deleted.capacity();
    }

  private:
    void traverse(Vec3f key, bool is_dir, std::vector<int32_t>& out) const;
    std::vector<BspNode> m_nodes;
    std::vector<BspBox> m_boxes;
    std::vector<uint8_t> m_parent_deleted;  // per input box
    BspStats m_stats;
};

}  // namespace lacuna
