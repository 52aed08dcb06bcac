// The closed set of skipping structures and the one switch that dispatches on them (STYLE.md
// habit 2): renderers call visit_accel once per frame and get the concrete type, whose cursor
// then inlines into the sample loop.
#pragma once
#include "accel/bitfield_octree.h"
#include "accel/brick_grid.h"
#include "accel/boolean_octree.h"
#include "accel/distance_map.h"
#include "accel/kdtree.h"
#include "accel/minmax_octree.h"
#include "accel/no_accel.h"

namespace lacuna {

template <class F>
decltype(auto) visit_accel(const Accel& a, F&& f) {
    switch (a.kind()) {
        case AccelKind::MinMax:
        case AccelKind::MinMaxInterval: return f(static_cast<const MinMaxOctree&>(a));
        case AccelKind::Bitfield: return f(static_cast<const BitfieldOctree&>(a));
        case AccelKind::Boolean: return f(static_cast<const BooleanOctree&>(a));
        case AccelKind::Distance:
        case AccelKind::Chebyshev: return f(static_cast<const DistanceMap&>(a));
        case AccelKind::KdTree: return f(static_cast<const KdTree&>(a));
        case AccelKind::Grid: return f(static_cast<const BrickGrid&>(a));
        case AccelKind::None: break;
    }
    return f(static_cast<const NoAccel&>(a));
}

}  // namespace lacuna
