// The registry of structures: one line per alternative of lacuna::Structure (lacuna/frame_spec.h)
// saying what it is called, which faces it has and how each face is built; the names, the kinds'
// list, the factories, the capabilities table and the tests follow from it.
//
// A structure has up to three faces, and each face is one renderer's way in:
//   ray     the cursor interface (src/accel/cursor.h): the stretches of a ray that may matter.
//           make_accel(kind) builds it through this table (`ray_face<T>`); the ray marcher takes
//           every structure with this face, the segment renderer's mask mode every one but `none`.
//   boxes   the box interface (src/slice/box_source.h): the non-empty boxes in visibility order.
//           The slicer takes these (`none` is the whole volume as one box, the 'Basic' slicer);
//           make_box_source(name) builds them through this table.
//   labels  the label bitfield octree, which only the segment renderer builds and walks.
// So a renderer's row of capabilities() is "the structures with my face", and iterating
// all_structures() through the session is the conformance suite for every renderer at once
// (tests/session/session_test.cpp). accel_names(), all_accel_kinds(), parse_accel(),
// box_source_names() and structure_of() read this table too: there is no second list.
//
// Adding a ray structure: its files in src/accel/, its AccelKind value (lacuna/accel.h) and its
// case in visit_accel (src/accel/accel_impl.h: the once-per-frame dispatch to the concrete type),
// an alternative of Structure with its parameters (lacuna/frame_spec.h), and one line here.
// Parameters of a new shape also need their two lines in frame_spec.cpp (accel_options and
// structure_of's fill) and their range check in validate_structure.
#pragma once
#include <iterator>
#include <memory>
#include <string>
#include <type_traits>
#include <optional>
#include <variant>

#include "accel/accel_impl.h"
#include "lacuna/accel.h"
#include "lacuna/frame_spec.h"
#include "slice/box_sources.h"
#include "slice/growing_boxes_source.h"

namespace lacuna::registry {

using RayFactory = std::unique_ptr<Accel> (*)(AccelKind, const Volume&, const AccelOptions&);
using BoxFactory = std::unique_ptr<BoxSource> (*)(const Volume&, const AccelOptions&,
                                                  const BoxesOptions&);

struct Entry {
    const char* name;              // the --accel name and structure_name()
    std::optional<AccelKind> ray;  // the AccelKind make_accel builds (nullopt: no ray face)
    RayFactory make_ray;           // builds the ray face (null: none)
    BoxFactory make_boxes;         // builds the box face the slicer takes (null: none)
    bool labels;                   // the segment renderer's label octree
    bool boxes() const { return make_boxes != nullptr; }
};

// The ray face of type T (src/accel/), by whichever constructor it has.
template <class T>
std::unique_ptr<Accel> ray_face(AccelKind k, const Volume& v, const AccelOptions& o) {
    if constexpr (std::is_constructible_v<T, AccelKind, const Volume&, const AccelOptions&>)
        return std::make_unique<T>(k, v, o);
    else if constexpr (std::is_constructible_v<T, const Volume&, const AccelOptions&>)
        return std::make_unique<T>(v, o);
    else
        return std::make_unique<T>();
}

// The box faces (src/slice/box_sources.h).
inline std::unique_ptr<BoxSource> whole_volume(const Volume& v, const AccelOptions&,
                                               const BoxesOptions&) {
    return std::make_unique<VolumeBoxSource>(v);
}
inline std::unique_ptr<BoxSource> kdtree_boxes(const Volume& v, const AccelOptions& o,
                                               const BoxesOptions&) {
    return make_kdtree_box_source(v, o);
}
inline std::unique_ptr<BoxSource> growing_boxes(const Volume& v, const AccelOptions& o,
                                                const BoxesOptions& b) {
    BoxesOptions bo = b;
    bo.threads = o.threads;
    validate(bo);
    return make_growing_boxes_source(v, bo);
}

inline constexpr Entry kStructures[] = {
    //  name             kind                       ray face                       box face       labels
    {"none",            AccelKind::None,            ray_face<NoAccel>,        whole_volume,  false},
    {"distance",        AccelKind::Distance,        ray_face<DistanceMap>,    nullptr,       false},
    {"chebyshev",       AccelKind::Chebyshev,       ray_face<DistanceMap>,    nullptr,       false},
    {"boolean",         AccelKind::Boolean,         ray_face<BooleanOctree>,  nullptr,       false},
    {"minmax",          AccelKind::MinMax,          ray_face<MinMaxOctree>,   nullptr,       false},
    {"bitfield",        AccelKind::Bitfield,        ray_face<BitfieldOctree>, nullptr,       false},
    {"kdtree",          AccelKind::KdTree,          ray_face<KdTree>,         kdtree_boxes,  false},
    {"minmax-interval", AccelKind::MinMaxInterval,  ray_face<MinMaxOctree>,   nullptr,       false},
    {"grid",            AccelKind::Grid,            ray_face<BrickGrid>,      nullptr,       false},
    {"boxes",           std::nullopt,               nullptr,                  growing_boxes, false},
    {"label-octree",    std::nullopt,               nullptr,                  nullptr,       true},
};
static_assert(std::size(kStructures) == std::variant_size_v<Structure>,
              "one registry entry per alternative of lacuna::Structure");

inline const Entry& entry(const Structure& s) { return kStructures[s.index()]; }
// The entry named `name` (nullptr: none).
inline const Entry* find(const std::string& name) {
    for (const Entry& e : kStructures)
        if (name == e.name) return &e;
    return nullptr;
}

// The octree traversal parameters, where a structure has them.
template <class T>
constexpr bool kHasOctree = requires(T t) { t.octree; };

}  // namespace lacuna::registry
