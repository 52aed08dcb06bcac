// What the three octrees share: the pyramid, traversal settings and the TF-domain check.
#pragma once
#include "accel/cell_ranges.h"
#include "accel/cursor.h"
#include "accel/octree.h"
#include "lacuna/accel.h"

namespace lacuna {

class OctreeBase : public Accel {
  public:
    const int* cells() const { return m_pyr.cells; }
    const Pyramid& pyramid() const { return m_pyr; }
    // The value -> LUT entry map the structure's ranges are in (that of the last TF).
    const ValueToLut& value_map() const { return m_map; }

  protected:
    OctreeBase(AccelKind k, const Volume& v, const AccelOptions& o)
        : Accel(k), m_volume(v), m_opts(o) {
        int c[3];
        cell_counts(v, c);
        m_pyr.init(c, o.leaf_cells);
        m_start =
            o.initial_level < 0 ? m_pyr.levels - 1 : std::min(o.initial_level, m_pyr.levels - 1);
        m_map = ValueToLut(v.vis_range(), kDefaultLutSize);
        m_vis = v.vis_range();
        m_lut_size = kDefaultLutSize;
    }
    // True if the LUT maps values differently from what the structure was built for (a TF file
    // with its own range, or another LUT size): the TF-independent part must be rebuilt.
    bool needs_rebuild(const TransferLut& lut) {
        if (lut.size() == m_lut_size && lut.vis.min == m_vis.min && lut.vis.max == m_vis.max)
            return false;
        m_vis = lut.vis;
        m_lut_size = lut.size();
        m_map = lut.map();
        return true;
    }

    const Volume& m_volume;
    AccelOptions m_opts;
    Pyramid m_pyr;
    int m_start = 0;
    ValueToLut m_map;
    ValueRange m_vis;
    int m_lut_size = 0;
};

}  // namespace lacuna
