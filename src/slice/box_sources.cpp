#include "slice/box_sources.h"

#include "accel/kdtree.h"
#include "lacuna/error.h"
#include "slice/growing_boxes_source.h"

namespace lacuna {

VolumeBoxSource::VolumeBoxSource(const Volume& v)
    : m_box{{0, 0, 0}, {v.dims().x - 1, v.dims().y - 1, v.dims().z - 1}} {}

namespace {

// The kd-tree subvolume list (kd-tree paper, Section 2.2) as the slicer renders it: the list
// boxes, near child of every split first.
class KdTreeBoxSource final : public BoxSource {
  public:
    KdTreeBoxSource(const Volume& v, const AccelOptions& o) : m_tree(v, o) {}
    void set_transfer_function(const TransferLut& lut) override { m_tree.set_transfer_function(lut); }
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

std::vector<std::string> box_source_names() { return {"none", "kdtree", "boxes"}; }

std::unique_ptr<BoxSource> make_box_source(const std::string& name, const Volume& volume,
                                           const AccelOptions& options, const BoxesOptions& boxes) {
    if (name == "none") return std::make_unique<VolumeBoxSource>(volume);
    if (name == "kdtree") return std::make_unique<KdTreeBoxSource>(volume, options);
    if (name == "boxes") {
        BoxesOptions bo = boxes;
        bo.threads = options.threads;
        validate(bo);
        return make_growing_boxes_source(volume, bo);
    }
    throw Error("--accel", "box source",
                "the slice renderer takes none, kdtree or boxes, not '" + name + "'");
}

}  // namespace lacuna
