// Box sources by name (the slicer's `--accel`): "none" is the whole volume as one box (the
// paper's 'Basic'), "kdtree" the kd-tree paper's subvolume list (non-empty leaves, front to back
// by the tree), "boxes" the growing boxes ordered by their orthogonal BSP tree.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/volume.h"
#include "slice/box_source.h"
#include "slice/growing_boxes.h"

namespace lacuna {

// The whole volume, one box [0, dims-1]: rendering it is the 'Basic' slicer.
class VolumeBoxSource final : public BoxSource {
  public:
    explicit VolumeBoxSource(const Volume& v);
    void set_transfer_function(const TransferLut&) override {}
    std::vector<CellBox> boxes_front_to_back(Vec3f) const override { return {m_box}; }
    std::vector<CellBox> boxes_front_to_back_along(Vec3f) const override { return {m_box}; }
    const char* name() const override { return "volume"; }

  private:
    CellBox m_box;
};

// The kd-tree paper's subvolume list (Section 2.2) as the slicer renders it: the list boxes, near
// child of every split first.
std::unique_ptr<BoxSource> make_kdtree_box_source(const Volume& volume,
                                                  const AccelOptions& options);

// Names make_box_source accepts: the registry's structures with a box face
// (src/session/structure_registry.h).
std::vector<std::string> box_source_names();
// Builds the source `name` over `volume` (which must outlive it). Throws lacuna::FrameError
// ("structure", ...) for an unknown name or one the slicer cannot use.
// "boxes" takes `boxes` (the paper's settings by default; its threads come from `options`).
std::unique_ptr<BoxSource> make_box_source(const std::string& name, const Volume& volume,
                                           const AccelOptions& options = {},
                                           const BoxesOptions& boxes = {});

}  // namespace lacuna
