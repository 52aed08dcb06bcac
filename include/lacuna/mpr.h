// Slice views (multi-planar reformatting, MPR): axial, coronal and sagittal planes through a world
// point, sampled with the ray marcher's own kernels, for the viewer's slice panes (issue 18).
//
// Why the same anatomy gives the same picture whatever the voxel order
//   A plane is chosen in world space (patient RAS mm, lacuna/orientation.h), never in index
//   space: pixel (c, r) sits at the world point  origin + c * u + r * v,  and its value is the
//   volume sampled at index A^-1 (world - t), A and t being the volume's index-to-world affine
//   (index_to_world). A volume stored in RAS, LPS or a permuted axis order holds the same voxels
//   at the same world points, so A^-1 sends each pixel to the same voxel of each copy: for
//   nearest sampling the values are equal, for trilinear they are the same 8 corners with the
//   same weights (up to float rounding of the index). The picture depends on the anatomy and the
//   plane alone.
//
// The display convention (3D Slicer's vtkMRMLSliceNode, "radiological" screens)
//   plane      screen right (+u)     screen up (-v)    normal
//   axial      patient left  (-x)    anterior (+y)     +z
//   coronal    patient left  (-x)    superior (+z)     +y
//   sagittal   posterior     (-y)    superior (+z)     +x   (the nose points left)
//   Image rows run top to bottom, so v, the step of one row, points down the screen.
//
// Extent and pixel size
//   The slice covers the volume's sampled box [0, dims-1] projected on the plane: the 8 world
//   corners' u and up coordinates give [u0, u1] x [w0, w1]. The default pixel is the smallest
//   voxel spacing p; width = floor((u1 - u0) / p) + 1 pixels with column c at u0 + c p, so when
//   the volume's axes are the patient's (any signed permutation), pixel centres fall on voxel
//   centres, one pixel per voxel, and nearest equals trilinear there. A max_size caps both sides
//   by coarsening p (the same extent, fewer pixels). The plane's offset along its normal is the
//   point's coordinate; nothing is clamped, a plane outside the volume is all NaN.
//
// Inside and outside
//   A pixel whose index lies in the sampled box (within kInsideTolerance voxels, which absorbs
//   the rounding of A^-1 at the faces) is sampled with kernel::trilinear or kernel::nearest
//   (src/render/ray_march_kernel.h, which clamp into the box as for every ray sample); any other
//   pixel is NaN, and window_level shows NaN black.
//
// Labels are sampled with kernel::nearest on their own grid and affine (the label map of
// docs/segments.md, never interpolated), and blended over the grey picture by their table
// colour times an opacity; label 0 and hidden labels leave the grey as it is.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/image.h"
#include "lacuna/math.h"
#include "lacuna/segments.h"
#include "lacuna/volume.h"

namespace lacuna {

enum class SlicePlane { Axial, Coronal, Sagittal };
std::string to_string(SlicePlane p);
// "axial", "coronal" or "sagittal"; throws lacuna::Error(where, "plane", ...) otherwise.
SlicePlane parse_slice_plane(const std::string& name, const std::string& where = "slice");

inline constexpr double kInsideTolerance = 1e-4;  // voxels, see "Inside and outside"

struct SliceOptions {
    double pixel_mm = 0;  // 0: the smallest voxel spacing
    int max_size = 0;     // 0: no cap; else width and height <= max_size (coarser pixels)
    Interpolation interpolation = Interpolation::Trilinear;
    int threads = 0;  // 0: all
};

// Where a slice's pixels are in the world: pixel (c, r) = origin + c * u + r * v (RAS mm).
struct SliceGeometry {
    SlicePlane plane = SlicePlane::Axial;
    int width = 0, height = 0;
    Vec3d origin, u, v;
    double pixel_mm = 0;
    Vec3d pixel_world(double c, double r) const { return origin + u * c + v * r; }
};
std::string to_string(const SliceGeometry& g);

// The plane through `point` (RAS mm) covering the volume's projected box. Throws lacuna::Error
// (where, field, ...) for a non-finite point, a pixel_mm that is not finite and positive, or a
// slice above kMaxSliceSide pixels per side.
inline constexpr int kMaxSliceSide = 16384;
SliceGeometry slice_geometry(const Volume& v, SlicePlane plane, Vec3d point,
                             const SliceOptions& o = {}, const std::string& where = "slice");

// Values at each pixel, row-major, top row first; NaN outside the volume.
struct Slice {
    SliceGeometry geometry;
    std::vector<float> values;
};
Slice sample_slice(const Volume& v, const SliceGeometry& g, Interpolation interp, int threads = 0);
Slice sample_slice(const Volume& v, SlicePlane plane, Vec3d point, const SliceOptions& o = {});

// Label values at each pixel of `g` (nearest voxel of the label map); -1 outside it.
std::vector<int32_t> sample_labels(const Volume& labels, const SliceGeometry& g, int threads = 0);

// Grey = clamp((value - (level - window / 2)) / window, 0, 1) * 255, rounded; NaN black; alpha
// 255. Throws lacuna::Error(where, "window", ...) unless window is finite and positive and level
// finite.
Image window_level(const Slice& s, double window, double level, const std::string& where = "slice");

// Blends each pixel with a visible, non-zero label towards the label's colour: out = grey +
// opacity * (colour - grey), opacity in [0, 1] (clamped).
void overlay_labels(Image& img, const std::vector<int32_t>& labels, const LabelTable& table,
                    float opacity);

// What a click shows: the value at a world point and where it is in the grid.
struct ProbeResult {
    Vec3d world;              // the point asked, RAS mm
    Vec3d index;              // continuous index A^-1 (world - t)
    bool inside = false;      // index within the sampled box (kInsideTolerance)
    Vec3i voxel{-1, -1, -1};  // nearest voxel (floor(index + 0.5)), when inside
    float value = 0;          // trilinear (or nearest) sample, when inside; NaN outside
    float voxel_value = 0;    // the nearest voxel's own value, when inside
    std::optional<int>
        label;  // the label map's nearest voxel at the point, when given and inside it
    std::string label_name;
};
ProbeResult probe(const Volume& v, Vec3d world, Interpolation interp = Interpolation::Trilinear,
                  const Volume* labels = nullptr, const LabelTable* table = nullptr);

}  // namespace lacuna
