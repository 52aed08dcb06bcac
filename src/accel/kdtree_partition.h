// The kd-tree empty-space partition of a classified cell grid (the kd-tree paper, Section 2):
//   step 1  classify every cell as empty or non-empty (by the TF, or by a value threshold)
//   step 2  the summed-volume table of the classification, in place (Eq. 5)
//   step 3  the kd-tree: split each node's box along its longest axis at the candidate plane of
//           least cost C = BV(left) + BV(right) (Eq. 1), until a halting criterion holds
//   step 4  the subvolume list: the leaves, or at most M boxes (Section 2.2)
// Build only: no rendering here. KdTree (kdtree.h) wraps it as an Accel for the ray marcher, and
// `lacuna partition` uses it directly (also with threshold classification, which is never used
// for rendering: a threshold says nothing about what the TF makes visible).
//
// Coordinates are cells (cell (i,j,k) spans voxels i..i+1, ...): a box [lo, hi) of cells is the
// index-space box [lo, hi], i.e. voxels lo..hi. A split plane p on axis a is the index-space plane
// x_a = p: the left child holds the cells < p, the right child the cells >= p.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "accel/region.h"
#include "accel/summed_volume_table.h"
#include "lacuna/accel.h"
#include "lacuna/math.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

// Typed settings of steps 3-4 (from AccelOptions or `lacuna partition`'s options).
struct KdSettings {
    int max_boxes = 0;         // M of Section 2.2; 0 = every leaf
    int delta = 0;             // candidate plane spacing Δl in cells; 0 = from the grid size
    float min_volume = 0.1f;   // halting 1: a node below this fraction of the grid is a leaf
    float min_gain = 0.05f;    // halting 2: a split must remove at least this fraction of the node
    int max_depth = 10;        // halting 3: the root has depth 0
    int threads = 0;           // 0 = all
    bool wide_counts = false;  // force the 64-bit table (tests); otherwise only when needed
};
// Validates (lacuna::Error naming the option on a bad value) and converts.
KdSettings kd_settings(const AccelOptions& o);
std::string to_string(const KdSettings& s);

// Δl of Section 2.1.3: the paper uses 4 for 256^3 and 8 for 512^3, i.e. at most 64 candidate
// planes on the longest axis: ceil(longest cell axis / 64), at least 1.
int default_kd_delta(const int cells[3]);

// One kd-tree node. Layout (48 bytes): the box, then the split, then bookkeeping.
//   box       BV of the non-empty cells the node holds, in cells [lo, hi); tight on all six sides
//             (each face slab holds a non-empty cell), so both halves of any plane strictly inside
//             it are non-empty and an interior node always has two children
//   left      index of the left child in the node array, the right child is left + 1; -1 = leaf
//   plane     split position in cells on `axis` (interior nodes): left < plane <= right
//   axis      0, 1, 2 (interior nodes), -1 for a leaf
//   depth     root = 0
//   leaves    leaves in the subtree (1 for a leaf): Ml and Mr of Section 2.2
//   non_empty non-empty cells in the box (from the table)
struct KdNode {
    CellBox box;
    int32_t left;
    int32_t plane;
    int16_t axis;
    int16_t depth;
    int32_t leaves;
    uint64_t non_empty;
    bool is_leaf() const { return left < 0; }
};
static_assert(sizeof(KdNode) == 48);

// Wall-clock seconds of the four steps of the last build.
struct KdTimings {
    double classify = 0;  // step 1 (including the row sums of Eq. 5, see summed_volume_table.h)
    double table = 0;     // step 2
    double tree = 0;      // step 3
    double list = 0;      // step 4
    double preprocess() const { return classify + table + tree; }  // the paper's Table 1 time
    double total() const { return classify + table + tree + list; }
};

// A candidate split of one node (Section 2.1.3) and its cost (Eq. 1, in cells).
struct KdSplit {
    bool valid = false;  // false: no candidate plane fits in the box
    int axis = 0, plane = 0;
    int64_t cost = 0;    // BV(left) + BV(right) volumes, cells
    int candidates = 0;  // planes evaluated
};
// The least-cost candidate plane on the longest axis of `box` (ties: the lowest axis, then the
// lowest plane). Planes are at box.lo + m*delta, m = 1, 2, ..., strictly inside the box.
template <class Count>
KdSplit choose_split(const SummedVolumeTable<Count>& t, const CellBox& box, int delta, int threads);

class KdPartition {
  public:
    KdPartition() = default;
    // "Everything may be visible": one leaf covering the whole grid (before any classification).
    explicit KdPartition(const int cells[3]);

    // Steps 1-4 with TF classification: a cell is non-empty when the TF has non-zero opacity on
    // some LUT entry between the map of its 8 corners' min and max (conservative for trilinear
    // interpolation, as in every other structure).
    void build_from_tf(const Volume& v, const TransferLut& lut, const KdSettings& s);
    // Steps 1-4 with the paper's own classification: a cell is non-empty when its largest corner
    // value is >= threshold (a trilinear sample can reach the threshold only then). For
    // `lacuna partition` only; never used for rendering.
    void build_from_threshold(const Volume& v, float threshold, const KdSettings& s);
    // Re-runs step 4 only, with another M (0 = all leaves).
    void make_list(int max_boxes);

    const int* cells() const { return m_cells; }
    const std::vector<KdNode>& nodes() const { return m_nodes; }
    // Node indices of the subvolume list, in tree order (left subtree first).
    const std::vector<int32_t>& list() const { return m_list; }
    bool in_list(int node) const { return m_in_list[size_t(node)] != 0; }
    std::vector<CellBox> boxes() const;
    // Front to back for a perspective eye (index space): the near child of every split first.
    // No box is behind a later one along any ray from the eye.
    std::vector<CellBox> boxes_in_visibility_order(Vec3f eye) const;
    // Front to back for parallel rays with direction `dir` (index space; orthographic views).
    std::vector<CellBox> boxes_in_visibility_order_along(Vec3f dir) const;

    uint64_t total_cells() const;
    uint64_t non_empty_cells() const { return m_non_empty; }
    uint64_t listed_cells() const;  // cells inside the list's boxes
    // Share of the grid outside the list's boxes (removed), and share of the empty cells removed.
    double removed_fraction() const;
    double removed_empty_fraction() const;
    int depth() const;
    const KdTimings& timings() const { return m_timings; }
    const KdSettings& settings() const { return m_settings; }
    int delta() const { return m_delta; }
    bool wide_counts() const { return m_wide; }
    size_t table_bytes() const { return m_t32.bytes() + m_t64.bytes(); }
    size_t bytes() const {
        return table_bytes() + m_nodes.capacity() * sizeof(KdNode) + m_in_list.capacity() +
               m_list.capacity() * sizeof(int32_t);
    }
    // The tables (tests): valid after a build, the one wide_counts() names.
    const SummedVolumeTable<uint32_t>& table32() const { return m_t32; }
    const SummedVolumeTable<uint64_t>& table64() const { return m_t64; }

    // The exact region answer for `cell`, descending from the root. Occupied: the list box that
    // holds the cell. Empty: a box of cells outside every list box — the part of a node's region
    // (the grid for the root, a half of the parent's box otherwise) outside the node's BV, cut
    // into at most six slabs, the one holding the cell. Every non-empty cell of a node's region
    // lies in its BV, so an empty answer never holds a non-empty cell.
    Region region(const int c[3]) const {
        CellBox outer{{0, 0, 0}, {m_cells[0], m_cells[1], m_cells[2]}};
        if (m_nodes.empty()) return {outer, true};
        int i = 0;
        for (;;) {
            const KdNode& n = m_nodes[size_t(i)];
            const CellBox& b = n.box;
            // 1. Outside the node's BV: the slab of `outer` minus the BV that holds the cell.
            for (int a = 0; a < 3; ++a) {
                if (c[a] < b.lo[a]) {
                    outer.hi[a] = b.lo[a];
                    return {outer, true};
                }
                if (c[a] >= b.hi[a]) {
                    outer.lo[a] = b.hi[a];
                    return {outer, true};
                }
                outer.lo[a] = b.lo[a];
                outer.hi[a] = b.hi[a];
            }
            // 2. Inside a list box: march through it.
            if (m_in_list[size_t(i)]) return {b, false};
            // 3. Interior node: descend into the half that holds the cell.
            if (c[n.axis] < n.plane) {
                outer.hi[n.axis] = n.plane;
                i = n.left;
            } else {
                outer.lo[n.axis] = n.plane;
                i = n.left + 1;
            }
        }
    }

  private:
    template <class Count>
    void build(SummedVolumeTable<Count>& t, const KdSettings& s);
    template <class Count>
    void split(const SummedVolumeTable<Count>& t, int node, int64_t min_volume);
    void reset_table(const int cells[3], const KdSettings& s);

    int m_cells[3] = {0, 0, 0};
    KdSettings m_settings;
    int m_delta = 1;
    bool m_wide = false;
    SummedVolumeTable<uint32_t> m_t32;
    SummedVolumeTable<uint64_t> m_t64;
    std::vector<KdNode> m_nodes;
    std::vector<uint8_t> m_in_list;  // per node: 1 when the node's box is in the list
    std::vector<int32_t> m_list;
    uint64_t m_non_empty = 0;
    KdTimings m_timings;
};

}  // namespace lacuna
