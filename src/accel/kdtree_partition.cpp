#include "accel/kdtree_partition.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "accel/cell_ranges.h"
#include "core/parallel.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Cell layers per work unit of the classification (one thread streams a slab plane by plane).
constexpr int kSlab = 8;

// Step 1, TF: per row, the visible flags of the cells summed along x (the row sums step 2
// starts from), written straight into the table.
template <class Count>
void classify_tf(const Volume& v, const TransferLut& lut, int threads,
                 SummedVolumeTable<Count>& t) {
    OpacityPrefix prefix;
    prefix.build(lut);
    for_each_cell_row(v, lut.map(), kSlab, threads, [&](const CellRow& r) {
        Count* row = t.row(r.j, r.k);
        Count s = 0;
        for (int i = 0; i < r.n; ++i) {
            s += Count(prefix.visible(r.lo[i], r.hi[i]));
            row[i] = s;
        }
    });
}

// Step 1, threshold: voxel flags (value >= threshold) of the two voxel planes of a cell layer,
// OR-reduced over each cell's 8 corners, then summed along x like classify_tf.
template <class Count, class T>
void classify_threshold_typed(const Volume& v, const T* data, float threshold, int threads,
                              SummedVolumeTable<Count>& t) {
    const Vec3i d = v.dims();
    const int cx = d.x - 1, cy = d.y - 1, cz = d.z - 1;
    const size_t plane = size_t(d.x) * size_t(d.y);
    parallel_for(size_t(cz), threads, [&](size_t k0, size_t k1) {
        std::vector<uint8_t> flags[2] = {std::vector<uint8_t>(plane), std::vector<uint8_t>(plane)};
        auto load = [&](int z, std::vector<uint8_t>& f) {
            const T* src = data + size_t(z) * plane;
            for (size_t i = 0; i < plane; ++i) f[i] = float(src[i]) >= threshold;
        };
        load(int(k0), flags[0]);
        for (size_t k = k0; k < k1; ++k) {
            std::vector<uint8_t>& a = flags[(k - k0) & 1];
            std::vector<uint8_t>& b = flags[((k - k0) & 1) ^ 1];
            load(int(k) + 1, b);
            for (int j = 0; j < cy; ++j) {
                const uint8_t* a0 = &a[size_t(j) * d.x];
                const uint8_t* a1 = a0 + d.x;
                const uint8_t* b0 = &b[size_t(j) * d.x];
                const uint8_t* b1 = b0 + d.x;
                Count* row = t.row(j, int(k));
                Count s = 0;
                for (int i = 0; i < cx; ++i) {
                    s += Count((a0[i] | a0[i + 1] | a1[i] | a1[i + 1] | b0[i] | b0[i + 1] | b1[i] |
                                b1[i + 1]) != 0);
                    row[i] = s;
                }
            }
        }
    });
}

// Appends the list of `node`'s subtree for a limit of m boxes (Section 2.2).
void list_limited(const std::vector<KdNode>& nodes, int node, int m, std::vector<int32_t>& out);

void list_leaves(const std::vector<KdNode>& nodes, int node, std::vector<int32_t>& out) {
    const KdNode& n = nodes[size_t(node)];
    if (n.is_leaf()) {
        out.push_back(node);
        return;
    }
    list_leaves(nodes, n.left, out);
    list_leaves(nodes, n.left + 1, out);
}

void list_limited(const std::vector<KdNode>& nodes, int node, int m, std::vector<int32_t>& out) {
    const KdNode& n = nodes[size_t(node)];
    // M = 1 or a leaf: the node itself.
    if (m <= 1 || n.is_leaf()) {
        out.push_back(node);
        return;
    }
    const int ml = nodes[size_t(n.left)].leaves, mr = nodes[size_t(n.left + 1)].leaves;
    // All the subtree's leaves fit: take them.
    if (ml + mr <= m) {
        list_leaves(nodes, node, out);
        return;
    }
    // Share m in proportion to the leaf counts. The paper gives both children the ceiling
    // ceil(M * Ml / (Ml + Mr)) and ceil(M * Mr / (Ml + Mr)), which can add up to M + 1 (M = 3,
    // Ml = Mr = 2); we give the left child the ceiling, kept in [1, M - 1], and the right child
    // the rest, so the list never exceeds M. Both shares stay <= the child's leaf count.
    int left_m = int((int64_t(m) * ml + ml + mr - 1) / (ml + mr));
    left_m = std::clamp(left_m, 1, m - 1);
    list_limited(nodes, n.left, left_m, out);
    list_limited(nodes, n.left + 1, m - left_m, out);
}

void visibility_order(const std::vector<KdNode>& nodes, const std::vector<uint8_t>& in_list,
                      int node, const float key[3], bool is_dir, std::vector<CellBox>& out) {
    const KdNode& n = nodes[size_t(node)];
    if (in_list[size_t(node)]) {
        out.push_back(n.box);
        return;
    }
    // The near side of the split plane first: the half holding the eye (perspective), or the
    // half the rays cross first (parallel rays: left first when they travel toward +axis).
    const bool left_first = is_dir ? key[n.axis] >= 0.f : key[n.axis] < float(n.plane);
    const int first = left_first ? n.left : n.left + 1;
    visibility_order(nodes, in_list, first, key, is_dir, out);
    visibility_order(nodes, in_list, first == n.left ? n.left + 1 : n.left, key, is_dir, out);
}

}  // namespace

int default_kd_delta(const int cells[3]) {
    const int longest = std::max({cells[0], cells[1], cells[2]});
    return std::max(1, (longest + 63) / 64);
}

KdSettings kd_settings(const AccelOptions& o) {
    KdSettings s;
    if (o.kd_max_boxes < 0)
        throw FrameError("structure.max_boxes",
                         "expected >= 0 (0 = every leaf), got " + std::to_string(o.kd_max_boxes));
    if (o.kd_delta < 0)
        throw FrameError("structure.delta", "expected >= 1 cells (0 = from the size), got " +
                                                std::to_string(o.kd_delta));
    if (!(o.kd_min_volume >= 0.f && o.kd_min_volume <= 1.f))
        throw FrameError("structure.min_volume",
                         "expected 0..1, got " + std::to_string(o.kd_min_volume));
    if (!(o.kd_min_gain >= 0.f && o.kd_min_gain <= 1.f))
        throw FrameError("structure.min_gain",
                         "expected 0..1, got " + std::to_string(o.kd_min_gain));
    if (o.kd_max_depth < 0 || o.kd_max_depth > 64)
        throw FrameError("structure.max_depth",
                         "expected 0..64, got " + std::to_string(o.kd_max_depth));
    s.max_boxes = o.kd_max_boxes;
    s.delta = o.kd_delta;
    s.min_volume = o.kd_min_volume;
    s.min_gain = o.kd_min_gain;
    s.max_depth = o.kd_max_depth;
    s.threads = o.threads;
    return s;
}

std::string to_string(const KdSettings& s) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "max_boxes %d delta %d min_volume %g min_gain %g max_depth %d%s",
                  s.max_boxes, s.delta, double(s.min_volume), double(s.min_gain), s.max_depth,
                  s.wide_counts ? " wide" : "");
    return buf;
}

template <class Count>
KdSplit choose_split(const SummedVolumeTable<Count>& t, const CellBox& box, int delta,
                     int threads) {
    KdSplit best;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (box.hi[a] - box.lo[a] > box.hi[axis] - box.lo[axis]) axis = a;
    const int lo = box.lo[axis], hi = box.hi[axis];
    const int m = (hi - lo - 1) / delta;  // planes lo + delta*c, c = 1..m, all < hi
    if (m < 1) return best;
    // Eq. 1 for every candidate: BV(left) + BV(right).
    std::vector<int64_t> cost(static_cast<size_t>(m));
    auto eval = [&](size_t c0, size_t c1) {
        for (size_t c = c0; c < c1; ++c) {
            const int p = lo + delta * int(c + 1);
            CellBox left = box, right = box, bv;
            left.hi[axis] = p;
            right.lo[axis] = p;
            int64_t sum = 0;
            if (bounding_volume(t, left, bv)) sum += box_volume(bv);
            if (bounding_volume(t, right, bv)) sum += box_volume(bv);
            cost[c] = sum;
        }
    };
    if (m >= 8 && threads != 1)
        parallel_for(size_t(m), threads, eval, 2);
    else
        eval(0, size_t(m));
    best.valid = true;
    best.axis = axis;
    best.candidates = m;
    best.cost = std::numeric_limits<int64_t>::max();
    for (int c = 0; c < m; ++c)
        if (cost[size_t(c)] < best.cost) {
            best.cost = cost[size_t(c)];
            best.plane = lo + delta * (c + 1);
        }
    return best;
}

template KdSplit choose_split(const SummedVolumeTable<uint32_t>&, const CellBox&, int, int);
template KdSplit choose_split(const SummedVolumeTable<uint64_t>&, const CellBox&, int, int);

KdPartition::KdPartition(const int cells[3]) {
    for (int a = 0; a < 3; ++a) m_cells[a] = cells[a];
    KdNode root{};
    root.box = CellBox{{0, 0, 0}, {cells[0], cells[1], cells[2]}};
    root.left = -1;
    root.axis = -1;
    root.leaves = 1;
    root.non_empty = total_cells();
    m_nodes = {root};
    m_non_empty = root.non_empty;
    make_list(0);
}

void KdPartition::reset_table(const int cells[3], const KdSettings& s) {
    for (int a = 0; a < 3; ++a) m_cells[a] = cells[a];
    m_settings = s;
    m_delta = s.delta > 0 ? s.delta : default_kd_delta(cells);
    // V2 of the last cell counts every non-empty cell: 32 bits suffice while the grid has at
    // most 2^32 - 1 cells.
    m_wide = s.wide_counts || total_cells() > uint64_t(std::numeric_limits<uint32_t>::max());
    if (m_wide) {
        m_t32 = {};
        m_t64.resize(cells);
    } else {
        m_t64 = {};
        m_t32.resize(cells);
    }
}

void KdPartition::build_from_tf(const Volume& v, const TransferLut& lut, const KdSettings& s) {
    int c[3];
    cell_counts(v, c);
    reset_table(c, s);
    const auto t0 = Clock::now();
    if (m_wide) {
        classify_tf(v, lut, s.threads, m_t64);
        m_timings.classify = seconds_since(t0);
        build(m_t64, s);
    } else {
        classify_tf(v, lut, s.threads, m_t32);
        m_timings.classify = seconds_since(t0);
        build(m_t32, s);
    }
}

void KdPartition::build_from_threshold(const Volume& v, float threshold, const KdSettings& s) {
    int c[3];
    cell_counts(v, c);
    reset_table(c, s);
    const auto t0 = Clock::now();
    visit_voxels(v, [&](const auto* data) {
        if (m_wide)
            classify_threshold_typed(v, data, threshold, s.threads, m_t64);
        else
            classify_threshold_typed(v, data, threshold, s.threads, m_t32);
    });
    m_timings.classify = seconds_since(t0);
    if (m_wide)
        build(m_t64, s);
    else
        build(m_t32, s);
}

template <class Count>
void KdPartition::build(SummedVolumeTable<Count>& t, const KdSettings& s) {
    // Step 2: complete Eq. 5 in place.
    auto t0 = Clock::now();
    t.build_from_row_sums();
    m_timings.table = seconds_since(t0);
    // Step 3: the root is the BV of the whole grid; split recursively.
    t0 = Clock::now();
    m_nodes.clear();
    m_non_empty = t.total();
    const CellBox grid{{0, 0, 0}, {m_cells[0], m_cells[1], m_cells[2]}};
    CellBox root_box;
    if (bounding_volume(t, grid, root_box)) {
        KdNode root{};
        root.box = root_box;
        root.left = -1;
        root.axis = -1;
        root.leaves = 1;
        root.non_empty = m_non_empty;
        m_nodes.push_back(root);
        // Halting 1 in cells: a node smaller than min_volume of the grid is a leaf.
        const int64_t min_volume = int64_t(std::ceil(double(s.min_volume) * double(total_cells())));
        split(t, 0, min_volume);
    }
    m_timings.tree = seconds_since(t0);
    // Step 4.
    make_list(s.max_boxes);
}

template <class Count>
void KdPartition::split(const SummedVolumeTable<Count>& t, int node, int64_t min_volume) {
    const KdNode n = m_nodes[size_t(node)];
    // Halting criteria: depth, node volume, then the best split's gain (Section 2.1.4).
    if (n.depth >= m_settings.max_depth) return;
    const int64_t volume = box_volume(n.box);
    if (volume < min_volume) return;
    const KdSplit sp = choose_split(t, n.box, m_delta, m_settings.threads);
    if (!sp.valid) return;
    // Eq. 2: the empty space the split removes.
    const int64_t removed = volume - sp.cost;
    if (double(removed) < double(m_settings.min_gain) * double(volume)) return;
    // Both halves of a plane strictly inside a tight box hold non-empty cells.
    KdNode child[2];
    for (int s = 0; s < 2; ++s) {
        CellBox half = n.box;
        if (s == 0)
            half.hi[sp.axis] = sp.plane;
        else
            half.lo[sp.axis] = sp.plane;
        child[s] = KdNode{};
        const bool ok = bounding_volume(t, half, child[s].box);
        if (!ok) return;  // cannot happen (tight boxes); stay a leaf rather than break invariants
        child[s].left = -1;
        child[s].axis = -1;
        child[s].depth = int16_t(n.depth + 1);
        child[s].leaves = 1;
        child[s].non_empty = uint64_t(t.count(child[s].box));
    }
    const int left = int(m_nodes.size());
    m_nodes.push_back(child[0]);
    m_nodes.push_back(child[1]);
    m_nodes[size_t(node)].left = left;
    m_nodes[size_t(node)].axis = int16_t(sp.axis);
    m_nodes[size_t(node)].plane = sp.plane;
    split(t, left, min_volume);
    split(t, left + 1, min_volume);
    m_nodes[size_t(node)].leaves = m_nodes[size_t(left)].leaves + m_nodes[size_t(left + 1)].leaves;
}

void KdPartition::make_list(int max_boxes) {
    const auto t0 = Clock::now();
    m_settings.max_boxes = max_boxes;
    m_list.clear();
    m_in_list.assign(m_nodes.size(), 0);
    if (!m_nodes.empty()) {
        if (max_boxes <= 0)
            list_leaves(m_nodes, 0, m_list);
        else
            list_limited(m_nodes, 0, max_boxes, m_list);
    }
    for (int32_t i : m_list) m_in_list[size_t(i)] = 1;
    m_timings.list = seconds_since(t0);
}

std::vector<CellBox> KdPartition::boxes() const {
    std::vector<CellBox> out;
    for (int32_t i : m_list) out.push_back(m_nodes[size_t(i)].box);
    return out;
}

std::vector<CellBox> KdPartition::boxes_in_visibility_order(Vec3f eye) const {
    std::vector<CellBox> out;
    const float key[3] = {eye.x, eye.y, eye.z};
    if (!m_nodes.empty()) visibility_order(m_nodes, m_in_list, 0, key, false, out);
    return out;
}

std::vector<CellBox> KdPartition::boxes_in_visibility_order_along(Vec3f dir) const {
    std::vector<CellBox> out;
    const float key[3] = {dir.x, dir.y, dir.z};
    if (!m_nodes.empty()) visibility_order(m_nodes, m_in_list, 0, key, true, out);
    return out;
}

uint64_t KdPartition::total_cells() const {
    return uint64_t(m_cells[0]) * uint64_t(m_cells[1]) * uint64_t(m_cells[2]);
}

uint64_t KdPartition::listed_cells() const {
    uint64_t s = 0;
    for (int32_t i : m_list) s += uint64_t(box_volume(m_nodes[size_t(i)].box));
    return s;
}

double KdPartition::removed_fraction() const {
    const uint64_t total = total_cells();
    return total ? double(total - listed_cells()) / double(total) : 0.0;
}

double KdPartition::removed_empty_fraction() const {
    const uint64_t empty = total_cells() - m_non_empty;
    return empty ? double(total_cells() - listed_cells()) / double(empty) : 1.0;
}

int KdPartition::depth() const {
    int d = 0;
    for (const KdNode& n : m_nodes) d = std::max(d, int(n.depth));
    return d;
}

}  // namespace lacuna
