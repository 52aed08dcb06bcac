// The registry of structures: one line per alternative of lacuna::Structure (lacuna/frame_spec.h)
// saying what it is called and which faces it has, from which the names, the capabilities table,
// the factories and the tests follow.
//
// A structure has up to three faces, and each face is one renderer's way in:
//   ray     the cursor interface (src/accel/cursor.h): the stretches of a ray that may matter.
//           Built by make_accel(kind) from src/accel/; the ray marcher takes every structure with
//           this face, the segment renderer's mask mode every one but `none`.
//   boxes   the box interface (src/slice/box_source.h): the non-empty boxes in visibility order.
//           The slicer takes these (`none` is the whole volume as one box, the 'Basic' slicer).
//   labels  the label bitfield octree, which only the segment renderer builds and walks.
// So a renderer's row of capabilities() is "the structures with my face", and iterating
// all_structures() through the session is the conformance suite for every renderer at once
// (tests/session/session_test.cpp).
//
// Adding a structure: its files in src/accel/ (or src/slice/), an alternative of Structure with
// its parameters, and one entry here (plus, for a ray structure, its AccelKind and
// make_accel case until src/accel/ reads this registry too).
#pragma once
#include <iterator>
#include <optional>
#include <variant>

#include "lacuna/accel.h"
#include "lacuna/frame_spec.h"

namespace lacuna::registry {

struct Entry {
    const char* name;              // the --accel name and structure_name()
    std::optional<AccelKind> ray;  // the AccelKind make_accel builds (nullopt: no ray face)
    bool boxes;                    // a box source the slicer takes (box_source_names())
    bool labels;                   // the segment renderer's label octree
};

// In the order of Structure's alternatives (entry() indexes it by variant index; the order is
// held by FrameSpec.StructureNamesAndKindsRoundTrip: structure_of(ray) has this entry's index).
inline constexpr Entry kStructures[] = {
    //  name               ray face                    boxes  labels
    {"none",            AccelKind::None,            true,  false},
    {"minmax",          AccelKind::MinMax,          false, false},
    {"minmax-interval", AccelKind::MinMaxInterval,  false, false},
    {"bitfield",        AccelKind::Bitfield,        false, false},
    {"boolean",         AccelKind::Boolean,         false, false},
    {"distance",        AccelKind::Distance,        false, false},
    {"chebyshev",       AccelKind::Chebyshev,       false, false},
    {"kdtree",          AccelKind::KdTree,          true,  false},
    {"grid",            AccelKind::Grid,            false, false},
    {"boxes",           std::nullopt,               true,  false},
    {"label-octree",    std::nullopt,               false, true},
};
static_assert(std::size(kStructures) == std::variant_size_v<Structure>,
              "one registry entry per alternative of lacuna::Structure");

inline const Entry& entry(const Structure& s) { return kStructures[s.index()]; }

// The octree traversal parameters, where a structure has them.
template <class T>
constexpr bool kHasOctree = requires(T t) { t.octree; };

}  // namespace lacuna::registry
