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
// Adding a structure: its files (src/accel/ for a ray face, src/slice/ for a box face), its
// alternative of Structure with its parameters (lacuna/frame_spec.h; a ray face also gets its
// AccelKind value in lacuna/accel.h) and one line in kTable below. Everything else follows from
// that line: the names, the factories, the capabilities table, the conformance tests, the
// benchmarks' columns, and visit_accel (the once-per-frame dispatch to the concrete type, below),
// which the renderers call through src/accel/accel_impl.h. Parameters of a new shape also need
// their lines in frame_spec.cpp (accel_options and structure_of's fill) and their range check in
// validate_structure.
#pragma once
#include <array>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <variant>

#include "accel/bitfield_octree.h"
#include "accel/boolean_octree.h"
#include "accel/brick_grid.h"
#include "accel/distance_map.h"
#include "accel/kdtree.h"
#include "accel/minmax_octree.h"
#include "accel/no_accel.h"
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

// One line per structure: the Structure alternative it describes, the concrete ray type (void:
// no ray face) with its AccelKind, and its name, box face and labels flag. The line's types are
// what visit_accel dispatches to; its values become the Entry that everything else reads.
template <class Spec, class Ray>
struct Line {
    using spec = Spec;  // the alternative of lacuna::Structure
    using ray = Ray;    // the ray face's concrete type, void when there is none
    Entry entry;
};
template <class Spec, class Ray = void>
constexpr Line<Spec, Ray> line(const char* name, std::optional<AccelKind> kind,
                               BoxFactory boxes = nullptr, bool labels = false) {
    if constexpr (std::is_void_v<Ray>)
        return {{name, kind, nullptr, boxes, labels}};
    else
        return {{name, kind, ray_face<Ray>, boxes, labels}};
}

inline constexpr std::tuple kTable{
    //   alternative                ray face         name, kind, box face, labels
    line<structure::None, NoAccel>("none", AccelKind::None, whole_volume),
    line<structure::Distance, DistanceMap>("distance", AccelKind::Distance),
    line<structure::Chebyshev, DistanceMap>("chebyshev", AccelKind::Chebyshev),
    line<structure::Boolean, BooleanOctree>("boolean", AccelKind::Boolean),
    line<structure::MinMax, MinMaxOctree>("minmax", AccelKind::MinMax),
    line<structure::Bitfield, BitfieldOctree>("bitfield", AccelKind::Bitfield),
    line<structure::KdTree, KdTree>("kdtree", AccelKind::KdTree, kdtree_boxes),
    line<structure::MinMaxInterval, MinMaxOctree>("minmax-interval", AccelKind::MinMaxInterval),
    line<structure::Grid, BrickGrid>("grid", AccelKind::Grid),
    line<structure::GrowingBoxes>("boxes", std::nullopt, growing_boxes),
    line<structure::LabelOctree>("label-octree", std::nullopt, nullptr, true),
};
inline constexpr size_t kCount = std::tuple_size_v<decltype(kTable)>;
template <size_t I>
using LineAt = std::remove_cvref_t<decltype(std::get<I>(kTable))>;

// Line I describes alternative I of Structure: the variant's order is the table's.
static_assert(kCount == std::variant_size_v<Structure>,
              "one registry line per alternative of lacuna::Structure");
template <size_t I>
constexpr bool kDescribes =
    std::is_same_v<typename LineAt<I>::spec, std::variant_alternative_t<I, Structure>>;
static_assert(
    []<size_t... I>(std::index_sequence<I...>) {
        return (kDescribes<I> && ...);
    }(std::make_index_sequence<kCount>{}),
    "registry line I must describe alternative I of Structure");

// The entries, in table order (what the names, factories and capabilities iterate).
inline constexpr std::array<Entry, kCount> kStructures =
    std::apply([](const auto&... l) { return std::array<Entry, kCount>{l.entry...}; }, kTable);

inline const Entry& entry(const Structure& s) {
    return kStructures[s.index()];
}
// The entry named `name` (nullptr: none).
inline const Entry* find(const std::string& name) {
    for (const Entry& e : kStructures)
        if (name == e.name) return &e;
    return nullptr;
}

// The octree traversal parameters, where a structure has them.
template <class T>
constexpr bool kHasOctree = requires(T t) {
    t.octree;
};

// ---- The dispatch to the concrete ray type (STYLE.md habit 2) --------------------------------
// visit_accel(a, f) calls f with `a` as the concrete type of the line whose kind is a.kind(),
// once per frame, so the cursor of that type inlines into the renderer's sample loop. The chain
// of kind tests is generated from kTable (a kind shared by two lines, none is, would take the
// first); a kind outside the table falls back to NoAccel, the reference (every sample).
template <size_t I, class F>
decltype(auto) visit_from(const Accel& a, F&& f) {
    if constexpr (I == kCount) {
        return f(static_cast<const NoAccel&>(a));
    } else {
        using Ray = typename LineAt<I>::ray;
        if constexpr (!std::is_void_v<Ray>)
            if (std::get<I>(kTable).entry.ray == a.kind()) return f(static_cast<const Ray&>(a));
        return visit_from<I + 1>(a, std::forward<F>(f));
    }
}

}  // namespace lacuna::registry

namespace lacuna {

template <class F>
decltype(auto) visit_accel(const Accel& a, F&& f) {
    return registry::visit_from<0>(a, std::forward<F>(f));
}

}  // namespace lacuna
