// The screen cover: which pixels' rays can meet a visible sample, from the grid's occupied
// bricks projected to the screen once per frame. A pixel outside it is written as the empty
// pixel without marching, so on sparse data most rays cost their set-up only.
//
// Why. On a sparse volume most rays that enter the volume's box meet nothing: on the 512^3 tree
// at 256^2, 94% of them. The leaping kernels cross such a ray in a few leaps, but each leap is a
// gather, a distance look-up and a crossing on the lanes' dependency chain, and those rays are
// where a sparse frame's time goes once the visible samples are few. Projecting the bricks
// answers the question for all of them at once, in the bricks' count, not the rays'.
//
// Exactness argument. Let U be the union of the occupied bricks' boxes (index space, cells
// [B b, B b + B] per axis) and U_m that union grown by m = 1 voxel. A sample reads a visible
// cell only at a position inside that cell's box, hence inside U; the sampler's positions are
// within far less than a voxel of the exact ray (the argument of accel/brick_grid.h), so a ray
// with a visible sample has an exact point in U_m. If the eye lies outside the grid's box grown
// by 2 voxels, that ray's first point y in U_m lies on the boundary of U_m. y is within m of
// some occupied brick Q. If all of Q's 26 neighbours were occupied, the cube of radius m < B
// around Q's box would lie in U, so y would be in U and its whole m-cube in U_m: y would be
// inside U_m, not on its boundary. So Q is a surface brick (BrickGrid::surface_runs), and the
// exact ray meets Q's box grown by m. The box is in front of the eye (boxes with a corner at or
// behind the eye plane switch the cover off), where the projection of a convex box is the convex
// hull of its projected corners: the pixel's centre is inside their bounding rectangle. That
// rectangle is rounded outward and grown by one pixel more for the float error of the
// projection, so the pixel is marked. An unmarked pixel's ray therefore has no visible sample,
// and its accumulated colour is exactly zero (zero-opacity entries are zero in every channel,
// ray_marcher.cpp step_corrected_lut): the empty pixel, with zero samples.
//
// Depth. The same argument bounds where along a covered ray its visible samples can be: every
// point of the boundary of U_m is within m of a surface brick (a point within m of a brick whose
// 26 neighbours are occupied is inside U_m), and the first and the last point of U_m on the ray
// are boundary points. So every visible sample's t lies between the nearest and the farthest
// point of the grown surface boxes the ray meets, and those boxes all reach the pixel's block.
// The marcher takes the lattice samples of [t0 - dt, t1 + dt] within the ray's box, still on the
// ray's own lattice (anchored at its entry, pixel_driver.h lattice_run rounds outward), so the
// samples it leaves out before and after are invisible, and the composite is unchanged.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "accel/brick_grid.h"
#include "lacuna/camera.h"
#include "lacuna/volume.h"

namespace lacuna {

class ScreenCover {
  public:
    // The cover of `grid`'s surface bricks for `cam` (the volume frame's camera) over `vol`, or
    // nothing (every pixel may be covered) when the grid has no surface runs yet (not refined for
    // this TF), the eye is near or inside the grid's box, or a brick reaches the eye plane.
    static std::optional<ScreenCover> build(const BrickGrid& grid, const Volume& vol,
                                            const Camera& cam);

    bool covered(int x, int y) const {
        return (m_bits[size_t(y) * m_words + size_t(x >> 6)] >> (x & 63)) & 1u;
    }
    // Bounds on the ray parameter (world units, as the marcher's t) of every visible sample of a
    // covered pixel's ray: per block of 8x8 pixels, the nearest and farthest point of the grown
    // surface boxes whose rectangles reach the block (the depth argument above).
    void depth(int x, int y, float& t0, float& t1) const {
        const size_t b = size_t(y >> 3) * size_t(m_bw) + size_t(x >> 3);
        t0 = m_t0[b], t1 = m_t1[b];
    }
    // Whether any pixel of [x0, x1) x [y0, y1) is covered.
    bool any(int x0, int y0, int x1, int y1) const;
    // The share of the image's pixels that are covered (benchmarks, tests).
    double fraction() const;
    int width() const { return m_width; }
    int height() const { return m_height; }

  private:
    void mark(int x0, int y0, int x1, int y1, float t0, float t1);  // inclusive, clipped
    int m_width = 0, m_height = 0, m_bw = 0;
    std::vector<float> m_t0, m_t1;  // per 8x8 block
    size_t m_words = 0;             // per row
    std::vector<uint64_t> m_bits;
};

}  // namespace lacuna
