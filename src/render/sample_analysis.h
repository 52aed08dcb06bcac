// The ideal sample count of a frame (the benchmarks' "ideal speedup").
//
// Of the samples the reference ray marcher takes, only those whose trilinear cell can produce a
// non-zero opacity can matter: the cell's 8 corners bound every sample in it, ValueToLut is
// monotone, so the cell can only read LUT entries in [map(min corner), map(max corner)]. A cell
// is *visible* when that entry range holds an entry with opacity > 0. No exact skipping structure
// built from per-cell value ranges may drop a sample of a visible cell, so
//
//     ideal speedup = samples of --accel none / samples in visible cells
//
// is the sample reduction a perfect structure (one that skips every invisible cell and nothing
// else) would reach. Both counts use the same lattice and the same early ray termination: a ray
// stops after the sample where its opacity reaches RenderOptions::ert, exactly as in the
// reference (skipped samples have opacity 0, and compositing them is the identity, so the
// accumulated opacity is bit for bit the reference's).
//
// Under nearest sampling (RenderOptions::interpolation) a sample reads one voxel, and a perfect
// structure drops exactly the samples whose voxel maps to a transparent entry: the count is then
// of samples whose own value is visible (the cells are not consulted).
//
// Cell ranges come from src/accel/cell_ranges.h, the structures' own raw material (float32
// corners widened by a relative 1e-6, conservative: a cell on a rounding boundary counts as
// visible).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

// One bit per cell: can this cell produce a sample with non-zero opacity under the LUT?
// Layout: cell (i,j,k) is bit i of row (j,k); each row starts on a fresh uint64 word (row_words
// words per row), so parallel builders never share a word.
class VisibleCells {
  public:
    VisibleCells(const Volume& v, const TransferLut& lut, int threads = 0);
    bool visible(int i, int j, int k) const {
        const uint64_t w = m_bits[row(j, k) + size_t(i >> 6)];
        return (w >> (i & 63)) & 1u;
    }
    const int* cells() const { return m_cells; }
    size_t cell_count() const { return size_t(m_cells[0]) * m_cells[1] * m_cells[2]; }
    size_t visible_count() const { return m_visible; }
    // The share of cells that are visible, in [0,1].
    double visible_fraction() const {
        return cell_count() ? double(m_visible) / double(cell_count()) : 0.;
    }

  private:
    size_t row(int j, int k) const {
        return (size_t(k) * size_t(m_cells[1]) + size_t(j)) * m_row_words;
    }
    int m_cells[3] = {0, 0, 0};
    size_t m_row_words = 0;
    size_t m_visible = 0;
    std::vector<uint64_t> m_bits;
};

// Samples of the reference lattice (ray_marcher.cpp) that lie in visible cells, summed over
// every pixel of `camera`, with early ray termination as in `options` (ert >= 1: none).
// Multithreaded over tiles; the count never depends on the thread count.
uint64_t count_visible_cell_samples(const Volume& volume, const TransferLut& lut,
                                    const VisibleCells& cells, const Camera& camera,
                                    const RenderOptions& options);
// Convenience: builds VisibleCells first (a pass over the volume).
uint64_t count_visible_cell_samples(const Volume& volume, const TransferLut& lut,
                                    const Camera& camera, const RenderOptions& options);

// Lattice samples of the reference march (no skipping, no early ray termination) summed over
// every pixel of `camera`: the same ray set-up and count as ray_marcher.cpp, without touching
// the voxels. `step` is in units of the smallest spacing (RenderOptions::step).
uint64_t count_lattice_samples(const Volume& volume, const Camera& camera, float step,
                               int threads = 0);

}  // namespace lacuna
