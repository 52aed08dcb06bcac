// What a skipping structure tells the cursor about the cell a ray is in, and the ray itself.
#pragma once
#include <cstdint>

namespace lacuna {

// The one ray of index space (voxel i at coordinate i on each axis): point(t) = o + t d, t in
// world units (Camera::generate's ray moved by the volume's inverse index-to-world map, so t is
// the same parameter in both spaces). Every consumer takes this type: the kernels and their
// lattices (render/ray_march_kernel.h), the cursors of every structure (accel/cursor.h,
// BrickGrid::Cursor), the sample analysis. o(a) and d(a) give the components by axis.
struct IndexRay {
    float ox, oy, oz, dx, dy, dz;
    float o(int a) const { return a == 0 ? ox : a == 1 ? oy : oz; }
    float d(int a) const { return a == 0 ? dx : a == 1 ? dy : dz; }
};

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
