// --accel distance and --accel chebyshev: distance maps at 1/4 resolution (bitfield paper's
// comparison structures). The grid of cells is cut into blocks of `distance_block` cells per
// axis; a block is occupied when any of its cells can produce a visible sample under the TF
// (so the downsampling is conservative). Each block stores its distance, in blocks, to the
// nearest occupied block: Euclidean (exact EDT, Felzenszwalb-Huttenlocher) or Chebyshev (exact,
// by a 26-neighbour wavefront). Both are rebuilt from the volume on every TF change.
//
// Skipping: from block b with distance D every block q with |q - b| < D is empty, so the cube
// of blocks of Chebyshev radius r around b is empty for r = D - 1 (Chebyshev) or the largest
// r < D / sqrt(3) (Euclidean: the cube inscribed in the empty ball).
//
// Layout: one uint16 per block (Chebyshev: distance; Euclidean: the cube radius r + 1 derived
// from the squared distance at build time, 0 = occupied).
#pragma once
#include <cstdint>
#include <vector>

#include "accel/cell_ranges.h"
#include "accel/cursor.h"
#include "lacuna/accel.h"

namespace lacuna {

class DistanceMap final : public Accel {
  public:
    DistanceMap(AccelKind kind, const Volume& v, const AccelOptions& o);
    void set_transfer_function(const TransferLut& lut) override;
    const int* cells() const { return m_cells; }
    Region region(const int cell[3], int&) const {
        int b[3];
        for (int a = 0; a < 3; ++a) b[a] = cell[a] / m_block;
        const uint16_t s = m_radius[(size_t(b[2]) * m_nb[1] + b[1]) * m_nb[0] + b[0]];
        Region reg;
        reg.empty = s != 0;
        const int r = s == 0 ? 0 : int(s) - 1;
        for (int a = 0; a < 3; ++a) {
            reg.box.lo[a] = std::max(0, b[a] - r) * m_block;
            reg.box.hi[a] = std::min(m_cells[a], (std::min(m_nb[a] - 1, b[a] + r) + 1) * m_block);
        }
        return reg;
    }
    using Cursor = RegionCursor<DistanceMap>;

  private:
    const Volume& m_volume;
    AccelOptions m_opts;
    int m_cells[3];
    int m_nb[3];
    int m_block;
    std::vector<uint16_t> m_radius;  // per block: 0 occupied, else empty cube radius + 1
};

}  // namespace lacuna
