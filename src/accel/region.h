// What a skipping structure tells the cursor about the cell a ray is in.
#pragma once
#include <cstdint>

namespace lacuna {

// A box of cells [lo, hi) in cell coordinates (cell (i,j,k) spans voxels i..i+1, ...), i.e. the
// index-space box [lo, hi]. Layout: 24 bytes, lo then hi, x y z.
struct CellBox {
    int lo[3];
    int hi[3];
};
static_assert(sizeof(CellBox) == 24);

// empty == true: every cell in `box` is invisible under the current TF (every sample whose
// trilinear cell lies in it has TF opacity exactly 0). empty == false: `box` contains the query
// cell and may hold visible cells; the cursor marches through it and asks again beyond it.
struct Region {
    CellBox box;
    bool empty;
};

}  // namespace lacuna
