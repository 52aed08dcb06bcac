#include "slice/growing_boxes_source.h"

#include <chrono>

#include "accel/cell_ranges.h"
#include "core/parallel.h"

namespace lacuna {

namespace {

double since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool thin(const CellBox& b, int t) {
    for (int a = 0; a < 3; ++a)
        if (b.hi[a] - b.lo[a] < t) return true;
    return false;
}

}  // namespace

GrowingBoxesSource::GrowingBoxesSource(const Volume& v, const BoxesOptions& o)
    : m_volume(v), m_opts(o) {
    // 1. Gradient cells and the growth (Section 3.1).
    const BoxMeasure measure(v, o);
    m_stats.gradient = measure.seconds();
    auto t0 = std::chrono::steady_clock::now();
    m_grown = grow_boxes(measure);
    m_stats.grow = since(t0);
    m_stats.grown = m_grown.size();
    for (const BoxInfo& b : m_grown) m_stats.grown_by_type[int(b.type)]++;

    // 2. BSP splitting (Section 3.2).
    int c[3];
    cell_counts(v, c);
    std::vector<CellBox> boxes(m_grown.size());
    for (size_t i = 0; i < boxes.size(); ++i) boxes[i] = m_grown[i].box;
    m_tree.build(boxes, CellBox{{0, 0, 0}, {c[0], c[1], c[2]}});
    m_stats.split = m_tree.stats().split_seconds;
    m_stats.after_split = m_tree.stats().leaves;
    m_stats.depth = m_tree.stats().depth;

    // 3. The facts of every leaf: original grown boxes keep theirs, pieces are measured. Types
    // are redetermined from the facts (BoxMeasure::type_of) for all of them.
    t0 = std::chrono::steady_clock::now();
    m_info.assign(m_tree.boxes().size(), BoxInfo{});
    {
        const std::vector<int32_t> leaves = m_tree.leaves();
        parallel_for(
            leaves.size(), o.threads,
            [&](size_t l0, size_t l1) {
                for (size_t l = l0; l < l1; ++l) {
                    const int32_t b = leaves[l];
                    if (size_t(b) < m_grown.size()) {
                        m_info[size_t(b)] = m_grown[size_t(b)];
                        m_info[size_t(b)].type = measure.type_of(m_grown[size_t(b)]);
                    } else {
                        m_info[size_t(b)] = measure.measure(m_tree.boxes()[size_t(b)].box);
                    }
                }
            },
            64);
    }
    m_stats.measure = since(t0);

    // 4. Bottom-up merging with the paper's three rules.
    if (o.merge) {
        m_tree.merge([&](int32_t a, int32_t b, const CellBox& merged) {
            const BoxInfo x = m_info[size_t(a)], y = m_info[size_t(b)];
            const BoxInfo u = measure.merge(x, y, merged);
            const bool rule1 = x.type == BoxType::Uniform && y.type == BoxType::Uniform &&
                               u.type == BoxType::Uniform;
            const bool rule2 = (x.type == BoxType::Other && y.type == BoxType::Other) ||
                               (x.type == BoxType::Gradient && y.type == BoxType::Gradient);
            const bool rule3 = thin(x.box, o.thin) || thin(y.box, o.thin);
            if (!(rule1 || rule2 || rule3)) return false;
            m_info.push_back(u);  // at the new box's index
            return true;
        });
        m_stats.merge = m_tree.stats().merge_seconds;
    }
    m_leaves = m_tree.leaves();
    m_stats.after_merge = m_leaves.size();
    m_stats.sub_volumes = m_tree.sub_volumes();
    m_slot.assign(m_tree.boxes().size(), -1);
    for (size_t l = 0; l < m_leaves.size(); ++l) {
        m_slot[size_t(m_leaves[l])] = int32_t(l);
        m_stats.final_by_type[int(m_info[size_t(m_leaves[l])].type)]++;
    }

    // 5. The per-leaf LUT-entry sets for the volume's own mapping (a TF with its own range
    // rebuilds them in set_transfer_function).
    std::vector<CellBox> leaf_boxes(m_leaves.size());
    for (size_t l = 0; l < m_leaves.size(); ++l)
        leaf_boxes[l] = m_tree.boxes()[size_t(m_leaves[l])].box;
    m_classifier.build(v, v.vis_range(), kDefaultLutSize, leaf_boxes, o.threads);
    m_stats.ranges = m_classifier.seconds();
    m_stats.intervals = m_classifier.intervals();
    m_empty.assign(m_leaves.size(), 0);  // everything may be visible until a TF is set
    make_cut();
}

// Bottom-up over the tree: the non-empty cells of every subtree; a subtree with none is skipped,
// one whose room is at most `coalesce` empty and `coalesce_edge` long (world units) on every
// axis is emitted
// whole, others descend. Children have
// larger indices than their parent (the tree is built top-down), so a reverse sweep is
// bottom-up.
void GrowingBoxesSource::make_cut() {
    const std::vector<BspNode>& nodes = m_tree.nodes();
    std::vector<double> full(nodes.size(), 0.0);
    const Vec3d sp = m_volume.spacing;
    auto short_enough = [&](const CellBox& r) {
        for (int a = 0; a < 3; ++a)
            if (double(r.hi[a] - r.lo[a]) * sp[a] > double(m_opts.coalesce_edge)) return false;
        return true;
    };
    m_cut.assign(nodes.size(), BspTree::kDescend);
    for (size_t i = nodes.size(); i-- > 0;) {
        const BspNode& n = nodes[i];
        if (n.is_leaf()) {
            const int32_t slot = n.box >= 0 ? m_slot[size_t(n.box)] : -1;
            const bool visible = slot >= 0 && !m_empty[size_t(slot)];
            full[i] = visible ? double(box_volume(n.room)) : 0.0;
            m_cut[i] = visible ? BspTree::kEmit : BspTree::kSkip;
            continue;
        }
        full[i] = full[size_t(n.low)] + full[size_t(n.low) + 1];
        if (full[i] == 0.0)
            m_cut[i] = BspTree::kSkip;
        else if (m_opts.coalesce >= 0.f &&
                 full[i] >= (1.0 - double(m_opts.coalesce)) * double(box_volume(n.room)) &&
                 short_enough(n.room))
            m_cut[i] = BspTree::kEmit;
    }
    // Count what a traversal emits (any view emits the same set).
    std::vector<int32_t> order;
    m_tree.order_cut(Vec3f{1, 1, 1}, true, m_cut, order);
    m_emitted = order.size();
    m_stats.emitted = m_emitted;
}

void GrowingBoxesSource::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!m_classifier.same_map(lut)) {
        std::vector<CellBox> leaf_boxes(m_leaves.size());
        for (size_t l = 0; l < m_leaves.size(); ++l)
            leaf_boxes[l] = m_tree.boxes()[size_t(m_leaves[l])].box;
        m_classifier.build(m_volume, lut.vis, lut.size(), leaf_boxes, m_opts.threads);
        m_stats.intervals = m_classifier.intervals();
    }
    m_classifier.classify(lut, m_empty);
    m_stats.empty = 0;
    for (uint8_t e : m_empty) m_stats.empty += e;
    make_cut();
    m_stats.classify = since(t0);
}

std::vector<CellBox> GrowingBoxesSource::emit(const std::vector<int32_t>& nodes) const {
    std::vector<CellBox> out;
    out.reserve(nodes.size());
    for (int32_t n : nodes) out.push_back(m_tree.nodes()[size_t(n)].room);
    return out;
}

std::vector<CellBox> GrowingBoxesSource::boxes_front_to_back(Vec3f eye) const {
    std::vector<int32_t> nodes;
    m_tree.order_cut(eye, false, m_cut, nodes);
    return emit(nodes);
}

std::vector<CellBox> GrowingBoxesSource::boxes_front_to_back_along(Vec3f dir) const {
    std::vector<int32_t> nodes;
    m_tree.order_cut(dir, true, m_cut, nodes);
    return emit(nodes);
}

size_t GrowingBoxesSource::bytes() const {
    return m_grown.capacity() * sizeof(BoxInfo) + m_tree.bytes() +
           m_info.capacity() * sizeof(BoxInfo) + m_leaves.capacity() * 4 + m_slot.capacity() * 4 +
           m_classifier.bytes() + m_empty.capacity();
}

std::unique_ptr<BoxSource> make_growing_boxes_source(const Volume& v, const BoxesOptions& o) {
    return std::make_unique<GrowingBoxesSource>(v, o);
}

}  // namespace lacuna
