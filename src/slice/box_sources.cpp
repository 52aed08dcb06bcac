#include "slice/box_sources.h"

#include "accel/kdtree.h"
#include "lacuna/error.h"
#include "session/structure_registry.h"

namespace lacuna {

VolumeBoxSource::VolumeBoxSource(const Volume& v)
    : m_box{{0, 0, 0}, {v.dims().x - 1, v.dims().y - 1, v.dims().z - 1}} {}

namespace {

// The kd-tree subvolume list (kd-tree paper, Section 2.2) as the slicer renders it: the list
// boxes, near child of every split first.
class KdTreeBoxSource final : public BoxSource {
  public:
    KdTreeBoxSource(const Volume& v, const AccelOptions& o) : m_tree(v, o) {}
    void set_transfer_function(const TransferLut& lut) override {
        m_tree.set_transfer_function(lut);
    }
    std::vector<CellBox> boxes_front_to_back(Vec3f eye) const override {
        return m_tree.boxes_in_visibility_order(eye);
    }
    std::vector<CellBox> boxes_front_to_back_along(Vec3f dir) const override {
        return m_tree.boxes_in_visibility_order_along(dir);
    }
    const char* name() const override { return "kdtree"; }

  private:
    KdTree m_tree;
};

}  // namespace

std::unique_ptr<BoxSource> make_kdtree_box_source(const Volume& volume,
                                                  const AccelOptions& options) {
    return std::make_unique<KdTreeBoxSource>(volume, options);
}

std::vector<std::string> box_source_names() {
    std::vector<std::string> out;
    for (const registry::Entry& e : registry::kStructures)
        if (e.boxes()) out.push_back(e.name);
    return out;
}

std::unique_ptr<BoxSource> make_box_source(const std::string& name, const Volume& volume,
                                           const AccelOptions& options, const BoxesOptions& boxes) {
    if (const registry::Entry* e = registry::find(name); e && e->make_boxes)
        return e->make_boxes(volume, options, boxes);
    std::string valid;
    for (const std::string& n : box_source_names()) valid += (valid.empty() ? "" : ", ") + n;
    throw FrameError("structure", "the slice renderer takes " + valid + ", not '" + name + "'");
}

}  // namespace lacuna
