// MIP and MinIP skipping through the value-range structures (docs/shading.md).
//
// For maximum-intensity projection only samples that can raise the ray's current maximum
// matter. Because the value -> LUT entry map is monotone, the LUT entry of the largest value is
// the largest LUT entry, so a ray can track its maximum in entries (integers: comparisons are
// exact) and skip every node that cannot produce an entry above it: the window [max + 1, last]
// (MinIP: [0, min - 1]). The window only shrinks while a ray marches, so a node found outside it
// stays outside it; the pixel (the TF at the extreme entry) is the unaccelerated one. Ties never
// change the maximum (a later sample must be strictly larger), so skipping equal entries is fine.
//
// Structures that keep value information per node (min-max octree: entry ranges; bitfield
// octree: bins) answer region_outside(cell, hint, lo, hi); the TF-dependent ones (boolean
// octree, distance maps, kd-tree) know only TF opacity and march MIP unaccelerated.
#pragma once
#include "accel/cursor.h"
#include "lacuna/transfer_function.h"

namespace lacuna {

template <class S>
concept HasEntryWindow = requires(const S& s, const int* c, int& h) {
    {s.region_outside(c, h, 0, 0)};
    {s.value_map()};
};

// A structure seen through a window of LUT entries the marcher updates between cursor steps:
// "empty" means no sample in the region has an entry in [*lo, *hi].
template <class S>
struct EntryWindowView {
    const S* s;
    const int* lo;
    const int* hi;
    const int* cells() const { return s->cells(); }
    Region region(const int cell[3], int& hint) const {
        return s->region_outside(cell, hint, *lo, *hi);
    }
};

inline bool same_map(const ValueToLut& a, const ValueToLut& b) {
    return a.offset() == b.offset() && a.scale() == b.scale() && a.last() == b.last();
}

}  // namespace lacuna
