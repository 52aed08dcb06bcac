// --accel boxes for the slice renderer: the growing boxes (Section 3.1) ordered by their
// orthogonal BSP tree (Section 3.2), as a BoxSource.
//
// Build (TF-independent, once per volume): gradient cells, growth, BSP splitting, bottom-up
// merging with the paper's three rules (BoxMeasure::type_of redetermines merged types), then the
// per-box LUT-entry sets of the final leaves (BoxClassifier). Per TF: which leaves are empty,
// O(intervals). Per view: one tree traversal, emitting the non-empty leaves front to back.
#pragma once
#include <memory>
#include <vector>

#include "slice/box_source.h"
#include "slice/bsp_tree.h"
#include "slice/growing_boxes.h"

namespace lacuna {

// Wall-clock seconds of the build steps, and counts for reports.
struct BoxesBuildStats {
    double gradient = 0, grow = 0, split = 0, merge = 0, measure = 0, ranges = 0;
    double classify = 0;  // last set_transfer_function (including a ranges rebuild, if any)
    size_t grown = 0, grown_by_type[3] = {0, 0, 0};  // indexed by BoxType
    size_t after_split = 0, after_merge = 0, final_by_type[3] = {0, 0, 0};
    size_t empty = 0;        // final leaves empty under the current TF
    size_t emitted = 0;      // boxes rendered under the current TF (after coalescing)
    size_t sub_volumes = 0;  // parentless leaves + live parents (the paper's textures)
    size_t intervals = 0;    // LUT-entry intervals kept by the classifier
    int depth = 0;
    double total() const { return gradient + grow + split + merge + measure + ranges; }
};

class GrowingBoxesSource final : public BoxSource {
  public:
    GrowingBoxesSource(const Volume& v, const BoxesOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    std::vector<CellBox> boxes_front_to_back(Vec3f eye_in_index_space) const override;
    std::vector<CellBox> boxes_front_to_back_along(Vec3f dir_in_index_space) const override;
    const char* name() const override { return "boxes"; }

    // For reports and tests: the grown boxes, the tree, the final leaves' facts (indexed like
    // tree().boxes(); only leaf entries are measured) and the current TF's empty flags.
    const std::vector<BoxInfo>& grown() const { return m_grown; }
    const BspTree& tree() const { return m_tree; }
    const BoxInfo& info(int32_t box) const { return m_info[size_t(box)]; }
    bool empty(int32_t box) const { return m_empty[size_t(m_slot[size_t(box)])] != 0; }
    const std::vector<int32_t>& leaves() const { return m_leaves; }   // final leaves, tree order
    const BoxClassifier& classifier() const { return m_classifier; }  // indexed like leaves()
    const BoxesBuildStats& stats() const { return m_stats; }
    size_t bytes() const;

    // The current TF's cut of the tree (BspTree::Cut per node) and the boxes it emits.
    const std::vector<uint8_t>& cut() const { return m_cut; }
    size_t emitted() const { return m_emitted; }

  private:
    void make_cut();
    std::vector<CellBox> emit(const std::vector<int32_t>& nodes) const;
    const Volume& m_volume;
    BoxesOptions m_opts;
    std::vector<BoxInfo> m_grown;
    BspTree m_tree;
    std::vector<BoxInfo> m_info;
    std::vector<int32_t> m_leaves;
    std::vector<int32_t> m_slot;  // box index -> position in m_leaves (-1: not a final leaf)
    BoxClassifier m_classifier;
    std::vector<uint8_t> m_empty;  // per final leaf (m_leaves order)
    std::vector<uint8_t> m_cut;    // per tree node: BspTree::Cut under the current TF
    size_t m_emitted = 0;          // boxes the cut emits
    BoxesBuildStats m_stats;
};

// The factory the slice renderer's `--accel boxes` uses. `v` must outlive the source.
std::unique_ptr<BoxSource> make_growing_boxes_source(const Volume& v, const BoxesOptions& o);

}  // namespace lacuna
