#include "slice/bsp_tree.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

#include "lacuna/error.h"
#include "slice/growing_boxes.h"

namespace lacuna {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool same(const CellBox& a, const CellBox& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

struct Plane {
    bool valid = false;
    int axis = 0, pos = 0;
    size_t cut = 0, larger = 0;  // boxes cut; boxes on the fuller side (cut boxes on both)
    bool better(const Plane& o) const {
        if (!o.valid) return true;
        if (cut != o.cut) return cut < o.cut;
        if (larger != o.larger) return larger < o.larger;
        if (axis != o.axis) return axis < o.axis;
        return pos < o.pos;
    }
};

// The split plane of a node: among the box faces strictly inside the room, fewest boxes cut
// (lo < p < hi), then the best balance. Per axis: sort the los and his, sweep the candidates.
Plane choose_plane(const std::vector<BspBox>& boxes, const std::vector<int32_t>& list,
                   const CellBox& room) {
    Plane best;
    const size_t n = list.size();
    std::vector<int> los(n), his(n);
    for (int a = 0; a < 3; ++a) {
        for (size_t i = 0; i < n; ++i) {
            los[i] = boxes[size_t(list[i])].box.lo[a];
            his[i] = boxes[size_t(list[i])].box.hi[a];
        }
        std::sort(los.begin(), los.end());
        std::sort(his.begin(), his.end());
        size_t below = 0, ended = 0;  // boxes with lo < p; boxes with hi <= p
        for (size_t i = 0; i < n; ++i) {
            const int p = los[i];
            if (p <= room.lo[a] || (i > 0 && los[i - 1] == p)) continue;
            below = i;  // los sorted: exactly i boxes start below p
            while (ended < n && his[ended] <= p) ++ended;
            Plane c;
            c.valid = true;
            c.axis = a;
            c.pos = p;
            c.cut = below - ended;
            c.larger = std::max(below, n - ended);
            if (c.better(best)) best = c;
        }
    }
    return best;
}

}  // namespace

void BspTree::build(const std::vector<CellBox>& input, const CellBox& room) {
    const auto t0 = std::chrono::steady_clock::now();
    m_nodes.clear();
    m_boxes.clear();
    m_stats = BspStats{};
    m_stats.input = input.size();
    m_parent_deleted.assign(input.size(), 0);
    for (size_t i = 0; i < input.size(); ++i) m_boxes.push_back(BspBox{input[i], int32_t(i), -1});

    struct Work {
        int32_t node;
        std::vector<int32_t> list;
        int depth;
    };
    std::vector<Work> stack;
    m_nodes.push_back(BspNode{room, -1, 0, 0, 0, -1});
    {
        std::vector<int32_t> all(input.size());
        for (size_t i = 0; i < all.size(); ++i) all[i] = int32_t(i);
        stack.push_back(Work{0, std::move(all), 0});
    }
    while (!stack.empty()) {
        Work w = std::move(stack.back());
        stack.pop_back();
        const CellBox r = m_nodes[size_t(w.node)].room;
        if (w.list.size() <= 1) {
            // A leaf: with a tiling, its one box is its room.
            if (w.list.empty() || !same(m_boxes[size_t(w.list[0])].box, r))
                throw Error("bsp tree", "boxes",
                            "do not tile the room " + to_string(r) + " (overlap or hole)");
            m_nodes[size_t(w.node)].box = w.list[0];
            m_stats.leaves++;
            m_stats.depth = std::max(m_stats.depth, w.depth);
            continue;
        }
        const Plane p = choose_plane(m_boxes, w.list, r);
        if (!p.valid) throw Error("bsp tree", "boxes", "overlap in the room " + to_string(r));
        // Lines 1-2: two children, the room split at the plane.
        const int32_t low = int32_t(m_nodes.size());
        CellBox rl = r, rh = r;
        rl.hi[p.axis] = p.pos;
        rh.lo[p.axis] = p.pos;
        m_nodes.push_back(BspNode{rl, -1, 0, 0, 0, -1});
        m_nodes.push_back(BspNode{rh, -1, 0, 0, 0, -1});
        BspNode& nd = m_nodes[size_t(w.node)];
        nd.low = low;
        nd.axis = int16_t(p.axis);
        nd.plane = p.pos;
        // Lines 3-16: boxes inside one side move there; cut boxes become two children of the
        // grown box they belong to (their parent, or themselves when original).
        std::vector<int32_t> ll, lh;
        for (int32_t id : w.list) {
            const BspBox b = m_boxes[size_t(id)];
            if (b.box.hi[p.axis] <= p.pos) {
                ll.push_back(id);
            } else if (b.box.lo[p.axis] >= p.pos) {
                lh.push_back(id);
            } else {
                BspBox x = b, y = b;
                x.box.hi[p.axis] = p.pos;
                y.box.lo[p.axis] = p.pos;
                x.parent = y.parent = b.grown;
                ll.push_back(int32_t(m_boxes.size()));
                m_boxes.push_back(x);
                lh.push_back(int32_t(m_boxes.size()));
                m_boxes.push_back(y);
                m_stats.cut++;
            }
        }
        stack.push_back(Work{low + 1, std::move(lh), w.depth + 1});
        stack.push_back(Work{low, std::move(ll), w.depth + 1});
    }
    m_stats.final_leaves = m_stats.leaves;
    m_stats.split_seconds = since(t0);
}

int32_t BspTree::parent_of(int32_t box) const {
    const int32_t p = m_boxes[size_t(box)].parent;
    return p >= 0 && !m_parent_deleted[size_t(p)] ? p : -1;
}

void BspTree::merge(const MergeRule& rule) {
    const auto t0 = std::chrono::steady_clock::now();
    // Children always have larger indices than their parent node: walking the nodes backwards
    // visits every subtree before its root, so merges cascade upwards in one pass.
    for (size_t i = m_nodes.size(); i-- > 0;) {
        BspNode& n = m_nodes[i];
        if (n.is_leaf()) continue;
        const BspNode& a = m_nodes[size_t(n.low)];
        const BspNode& b = m_nodes[size_t(n.low) + 1];
        if (!a.is_leaf() || !b.is_leaf()) continue;
        if (!rule(a.box, b.box, n.room)) continue;
        const int32_t pa = parent_of(a.box), pb = parent_of(b.box);
        BspBox m{n.room, -1, -1};
        if (pa == pb && pa >= 0) {
            // Two pieces of one grown box: a bigger piece of it, or the whole box again.
            m.grown = pa;
            m.parent = same(m_boxes[size_t(pa)].box, n.room) ? -1 : pa;
        } else if (pa != pb) {
            if (pa >= 0) m_parent_deleted[size_t(pa)] = 1;
            if (pb >= 0) m_parent_deleted[size_t(pb)] = 1;
        }
        m_boxes.push_back(m);
        BspNode& nn = m_nodes[i];  // rule() cannot touch m_nodes, but stay safe
        nn.low = -1;
        nn.box = int32_t(m_boxes.size() - 1);
        m_stats.merged++;
    }
    m_stats.final_leaves = leaves().size();
    m_stats.merge_seconds = since(t0);
}

std::vector<int32_t> BspTree::leaves() const {
    std::vector<int32_t> out;
    traverse(Vec3f{1, 1, 1}, true, out);
    return out;
}

size_t BspTree::sub_volumes() const {
    std::vector<uint8_t> seen(m_parent_deleted.size(), 0);
    size_t n = 0;
    for (int32_t b : leaves()) {
        const int32_t p = parent_of(b);
        if (p < 0)
            ++n;
        else if (!seen[size_t(p)]) {
            seen[size_t(p)] = 1;
            ++n;
        }
    }
    return n;
}

void BspTree::order_cut(Vec3f key, bool is_dir, const std::vector<uint8_t>& cut,
                        std::vector<int32_t>& out) const {
    out.clear();
    if (m_nodes.empty()) return;
    std::vector<int32_t> stack{0};
    while (!stack.empty()) {
        const int32_t i = stack.back();
        stack.pop_back();
        const BspNode& n = m_nodes[size_t(i)];
        if (cut[size_t(i)] == kSkip) continue;
        if (cut[size_t(i)] == kEmit || n.is_leaf()) {
            out.push_back(i);
            continue;
        }
        const bool low_first = is_dir ? key[n.axis] >= 0.f : key[n.axis] < float(n.plane);
        stack.push_back(low_first ? n.low + 1 : n.low);
        stack.push_back(low_first ? n.low : n.low + 1);
    }
}

void BspTree::traverse(Vec3f key, bool is_dir, std::vector<int32_t>& out) const {
    out.clear();
    if (m_nodes.empty()) return;
    std::vector<int32_t> stack{0};
    while (!stack.empty()) {
        const BspNode& n = m_nodes[size_t(stack.back())];
        stack.pop_back();
        if (n.is_leaf()) {
            out.push_back(n.box);
            continue;
        }
        // The near side first: pushed last.
        const bool low_first = is_dir ? key[n.axis] >= 0.f : key[n.axis] < float(n.plane);
        stack.push_back(low_first ? n.low + 1 : n.low);
        stack.push_back(low_first ? n.low : n.low + 1);
    }
}

}  // namespace lacuna
