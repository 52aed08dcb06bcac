// The index frame `lacuna partition` builds its pictures and lists in (issue 14): the file's
// voxels reordered, exactly, so the index axes point toward the patient's right, anterior and
// superior (RAS order).
//
// Why: the kd-tree splits a node's longest axis (ties: the lower index axis) at candidate planes
// counted from the node's low index end, keeping the first of equal costs, and the growing boxes
// grow from the first free block in x-fastest order; both depend on the voxel order, so one anatomy
// stored RAS, LPS or in a sagittal order would give three different sets of boxes. Built on the
// reordered voxels, every storage whose axes differ from another's by a permutation and flips (a
// signed permutation of the index axes, which moves no voxel off the lattice) gives the same voxels
// in the same order, hence the same boxes, bit for bit, at the same world positions. What is
// rendered is still rendered from the file's own voxels and structures (exact against --accel
// none); only the boxes drawn and listed come from the reordered copy.
//
// Which file axis becomes which: the free index axis most along superior first, then the one
// most along right, then the last, each reversed when it points the other way (inferior, left,
// posterior). An oblique file is reordered to its nearest axes; axes exactly at 45 degrees go
// to the lower file axis, so two storages of such a file may still differ.
#pragma once
#include <array>
#include <nlohmann/json.hpp>
#include <string>

#include "accel/region.h"
#include "lacuna/math.h"
#include "lacuna/volume.h"

namespace lacuna::cli {

struct RasOrder {
    std::array<int, 3> axis{0, 1, 2};  // RAS-order axis a is the file's index axis axis[a]
    std::array<bool, 3> flip{false, false, false};  // ... reversed
    bool identity() const {
        return axis == std::array<int, 3>{0, 1, 2} && !flip[0] && !flip[1] && !flip[2];
    }
};

// The nearest RAS order of v's index axes. Identity for a volume without geometry.
RasOrder ras_order(const Volume& v);

// v's voxels in RAS order: voxel (i,j,k) of the result is v's voxel at the same world position
// (the geometry is rewritten to keep it), with v's spacing permuted, its visualization range and
// its geometry source. A new buffer; v is not touched.
Volume reorder(const Volume& v, const RasOrder& o);

// A box of cells of the RAS-order copy as a box of cells of the file (`file_dims`: the file's
// voxel dims): the same cells.
CellBox to_file_cells(const CellBox& b, const RasOrder& o, Vec3i file_dims);
// A point of the RAS-order copy's index space in the file's index space.
Vec3f to_file_index(Vec3f p, const RasOrder& o, Vec3i file_dims);

// The world (patient RAS, mm) bounding box of the voxels lo..hi of cell box `b` of `v`: the box
// itself when v's axes are the world's, else the box around its eight corners.
void world_box(const Volume& v, const CellBox& b, double lo[3], double hi[3]);

// A box of the RAS-order copy in partition's JSON: the file's voxels lo..hi, its cell count and
// its world box (mm, rounded to 1e-6 so the same anatomy prints the same numbers).
nlohmann::json box_json(const CellBox& box, const Volume& file, const RasOrder& o);

// The JSON description of the reordering ("ras_order" in partition's JSON).
std::string to_string(const RasOrder& o);

}  // namespace lacuna::cli
