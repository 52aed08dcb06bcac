// Volume: a scalar grid of uint8, int16, uint16 or float32 voxels, x fastest, then y, then z.
//
// Coordinate spaces
//   index space   voxel (i,j,k) sits at the integer point (i,j,k); the sampled region is the box
//                 [0, dims-1], so trilinear samples never leave the grid (VTK's convention).
//   cell          cell (i,j,k) is the cube between voxels i..i+1, j..j+1, k..k+1; there are
//                 (dims-1) cells per axis. A trilinear sample in a cell lies between the min and
//                 max of its 8 corner voxels, which is why skipping structures work per cell.
//   world space   patient RAS in millimetres: world = direction * (index * spacing) + origin,
//                 with direction and origin stored in ITK's LPS+ form (lacuna/orientation.h
//                 converts, docs/formats.md "World frame"). The defaults (geometry never set:
//                 synthetic volumes, raw files) make world = index * spacing.
//
// Visualization range (bitfield paper, Section 3.1): the interval of voxel values that the
// transfer function's domain [0,1] maps onto. Data min..max by default, overridable.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "lacuna/math.h"

namespace lacuna {

enum class VoxelType : uint8_t { UInt8, Int16, UInt16, Float32 };

std::string to_string(VoxelType t);
// Parses "uint8", "int16", "uint16", "float32" (also "float"); throws lacuna::Error otherwise.
VoxelType parse_voxel_type(const std::string& name, const std::string& where = "type");
size_t voxel_size(VoxelType t);

template <class T>
constexpr VoxelType voxel_type_of();
template <>
constexpr VoxelType voxel_type_of<uint8_t>() {
    return VoxelType::UInt8;
}
template <>
constexpr VoxelType voxel_type_of<int16_t>() {
    return VoxelType::Int16;
}
template <>
constexpr VoxelType voxel_type_of<uint16_t>() {
    return VoxelType::UInt16;
}
template <>
constexpr VoxelType voxel_type_of<float>() {
    return VoxelType::Float32;
}

struct ValueRange {
    float min = 0.f, max = 0.f;
    float width() const { return max - min; }
};

// Largest grid lacuna accepts: each axis in [2, 32768]; total bytes must also fit in memory
// (checked by Volume's constructor against the machine's physical memory).
inline constexpr int kMaxDim = 32768;

class Volume {
  public:
    Volume() = default;
    // Allocates dims.x*dims.y*dims.z voxels (zeroed). `where` names the source in errors.
    // Throws lacuna::Error for dims < 2, > kMaxDim, or more bytes than physical memory.
    Volume(Vec3i dims, VoxelType type, const std::string& where = "volume");
    // Adopts an existing buffer (e.g. from ITK's reader) without copying; `owner` keeps it alive.
    Volume(Vec3i dims, VoxelType type, std::shared_ptr<void> owner, void* data);

    Vec3i dims() const { return m_dims; }
    VoxelType type() const { return m_type; }
    size_t voxel_count() const { return size_t(m_dims.x) * size_t(m_dims.y) * size_t(m_dims.z); }
    size_t bytes() const { return voxel_count() * voxel_size(m_type); }
    size_t index(int i, int j, int k) const {
        return (size_t(k) * size_t(m_dims.y) + size_t(j)) * size_t(m_dims.x) + size_t(i);
    }

    void* data() { return m_data; }
    const void* data() const { return m_data; }
    template <class T>
    T* data_as() {
        return static_cast<T*>(m_data);
    }
    template <class T>
    const T* data_as() const {
        return static_cast<const T*>(m_data);
    }

    // Voxel value converted to float (slow path: tests, info, generators).
    float value(int i, int j, int k) const;
    void set_value(int i, int j, int k, float v);

    Vec3d spacing{1, 1, 1};  // mm between voxel centres
    // Geometry in ITK's LPS+ convention (x toward the patient's left, y posterior, z superior),
    // whatever the file's own convention: the world position of voxel (0,0,0), and the
    // row-major direction cosines (column c = the LPS direction of index axis c). The default
    // LPS diag(-1, -1, 1) is RAS identity: world = index * spacing.
    Vec3d origin{0, 0, 0};
    double direction[9] = {-1, 0, 0, 0, -1, 0, 0, 0, 1};
    // Where the geometry came from, for `lacuna info` ("NIfTI sform (code 1, scanner)", "DICOM
    // ImageOrientationPatient/ImagePositionPatient", ...); empty: none (index * spacing).
    std::string geometry_source;

    // Scans the voxels: sets data_range (and vis_range if it was never set: the data range, or
    // [min, min+1] when that is empty or too narrow for the LUT, see lut_range_ok). For float32,
    // throws lacuna::Error(where, "voxel (i,j,k)", "NaN/Inf") on the first non-finite voxel and
    // lacuna::Error(where, "voxel values", ...) when max - min overflows float.
    void compute_range(const std::string& where = "volume");
    // NaN voxels (float32 only) are background: resampled or masked MRI often holds NaN outside
    // the brain. This replaces each by the smallest finite voxel value, so it renders as that
    // value does (transparent under any TF whose opacity at the range minimum is zero: every
    // built-in and Slicer preset), and returns how many it replaced (also kept in nan_voxels).
    // Inf stays an error (compute_range). A volume of NaN only: lacuna::Error(where,
    // "voxel values", ...). The file readers call it before compute_range (docs/formats.md).
    size_t replace_nan_with_minimum(const std::string& where = "volume");
    size_t nan_voxels = 0;
    ValueRange data_range() const { return m_data_range; }
    ValueRange vis_range() const { return m_vis_range; }
    // Overrides the visualization range; throws lacuna::Error if min >= max, not finite, or too
    // narrow for the LUT's float scale (check_lut_range).
    void set_vis_range(ValueRange r);

    // Physical extent of the sampled region [0, dims-1] * spacing (world units).
    Vec3f world_extent() const;

  private:
    Vec3i m_dims{0, 0, 0};
    VoxelType m_type = VoxelType::UInt8;
    std::shared_ptr<void> m_owner;
    void* m_data = nullptr;
    ValueRange m_data_range{};
    ValueRange m_vis_range{};
    bool m_vis_set = false;
};

std::string to_string(const Volume& v);

// Calls f(const T* data) with the volume's concrete voxel type: the one place where the voxel
// type is dispatched (STYLE.md habit 2).
template <class F>
decltype(auto) visit_voxels(const Volume& v, F&& f) {
    switch (v.type()) {
        case VoxelType::UInt8:
            return f(v.data_as<uint8_t>());
        case VoxelType::Int16:
            return f(v.data_as<int16_t>());
        case VoxelType::UInt16:
            return f(v.data_as<uint16_t>());
        default:
            return f(v.data_as<float>());
    }
}

}  // namespace lacuna
