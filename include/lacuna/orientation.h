// Patient orientation: the index-to-world affine of a volume and the frame the renderers use.
//
// Coordinate spaces (docs/formats.md, "World frame")
//   index space    voxel (i,j,k) at the integer point (i,j,k), as in lacuna/volume.h.
//   world space    patient RAS in millimetres (3D Slicer's convention): +x toward the patient's
//                  right, +y anterior, +z superior. world = A * (i,j,k) + t, the file's affine.
//                  Volume::origin and Volume::direction hold ITK's LPS+ form of the same map
//                  (x and y negated); index_to_world() converts.
//   volume frame   index * spacing (mm), the frame the ray marcher, the skipping structures and
//                  every feature work in: world = R * q + t with q = index * spacing and R the
//                  direction in RAS (orthonormal: a rotation, possibly with a flip). A rigid map,
//                  so distances (ray parameters t, step lengths) and dot products (shading) are
//                  the same in world and in the volume frame.
//
// A volume whose geometry was never set (synthetic volumes, raw files) has R = identity and t = 0:
// its world is index * spacing, the frame the renderers used before orientation existed.
#pragma once
#include <string>

#include "lacuna/camera.h"
#include "lacuna/math.h"
#include "lacuna/volume.h"

namespace lacuna {

// world = m * (i, j, k) + t; row-major, millimetres, RAS.
struct Affine {
    double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    double t[3] = {0, 0, 0};
    Vec3d apply(Vec3d p) const;
    double column_length(int c) const;
};
std::string to_string(const Affine& a);

// The volume's index-to-world (RAS) affine: the LPS direction and origin with x and y negated,
// columns scaled by spacing.
Affine index_to_world(const Volume& v);

// Three letters, the world direction each index axis points toward (+i, +j, +k), nibabel's
// aff2axcodes convention: "RAS" for ch2, "LPS" for a standard axial DICOM series, "LPI" ... An
// oblique axis is named by its largest component.
std::string orientation_code(const Volume& v);

// The world (RAS, mm) axis-aligned bounding box of the sampled region [0, dims-1].
Box3f world_bounds(const Volume& v);

// Throws lacuna::Error(where, field, ...) unless spacing is finite and positive, origin finite,
// and direction finite with orthonormal columns within 1e-4 (a rotation, possibly with a flip):
// a zero, singular, non-finite or sheared geometry is refused, naming the field. Also refused,
// as the renderers' float positions cannot hold it (a picture would come out empty): spacing
// below 1e-15 mm, a volume more than 1e15 mm across or with a corner beyond 1e15 mm ("spacing",
// "origin"), and one further from the world origin than both twice its size and 2^19 of its
// finest spacing ("origin").
void check_geometry(const Volume& v, const std::string& where);

// The rigid map from world (RAS) to the volume frame: q = rot * (p - from). `identity` when it
// is exactly the identity (no orientation), so callers can skip it and keep every bit.
struct VolumeFrame {
    double rot[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // R^T: rows are the index axes in world
    Vec3d from{0, 0, 0};                                   // the world position of voxel (0,0,0)
    bool identity = true;
    Vec3f point(Vec3f world) const;   // world point -> volume frame
    Vec3f vector(Vec3f world) const;  // world direction -> volume frame
    // True when rot is a signed permutation (the axes of the two frames are parallel), so an
    // axis-aligned world box is an axis-aligned box in the volume frame.
    bool axis_aligned() const;
};
VolumeFrame volume_frame(const Volume& v);

// The camera moved into the volume frame: its eye and basis mapped by `f`. Every ray it generates
// is the world camera's ray mapped by `f` (the map is affine; only rounding of the basis
// differs), and the scalar and batched ray set-ups both start from this one camera.
Camera to_volume_frame(const VolumeFrame& f, const Camera& world_camera);

}  // namespace lacuna
