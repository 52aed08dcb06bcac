#include "lacuna/volume.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"

namespace lacuna {

std::string to_string(VoxelType t) {
    switch (t) {
        case VoxelType::UInt8:
            return "uint8";
        case VoxelType::Int16:
            return "int16";
        case VoxelType::UInt16:
            return "uint16";
        case VoxelType::Float32:
            return "float32";
    }
    return "?";
}

VoxelType parse_voxel_type(const std::string& name, const std::string& where) {
    if (name == "uint8" || name == "u8") return VoxelType::UInt8;
    if (name == "int16" || name == "i16") return VoxelType::Int16;
    if (name == "uint16" || name == "u16") return VoxelType::UInt16;
    if (name == "float32" || name == "float" || name == "f32") return VoxelType::Float32;
    throw Error(where, "voxel type",
                "expected uint8, int16, uint16 or float32, got '" + name + "'");
}

size_t voxel_size(VoxelType t) {
    switch (t) {
        case VoxelType::UInt8:
            return 1;
        case VoxelType::Int16:
        case VoxelType::UInt16:
            return 2;
        case VoxelType::Float32:
            return 4;
    }
    return 1;
}

static size_t physical_memory_bytes() {
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return size_t(1) << 40;
    return size_t(pages) * size_t(page);
}

static void check_dims(Vec3i dims, VoxelType type, const std::string& where) {
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 2 || dims[a] > kMaxDim)
            throw Error(where, "dims",
                        "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                            std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                            std::to_string(dims.z));
    }
    // kMaxDim^3 * 4 < 2^47, so this product cannot overflow size_t.
    size_t bytes = size_t(dims.x) * size_t(dims.y) * size_t(dims.z) * voxel_size(type);
    size_t phys = physical_memory_bytes();
    if (bytes > phys)
        throw Error(where, "dims",
                    "a " + std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" +
                        std::to_string(dims.z) + " " + to_string(type) + " volume needs " +
                        std::to_string(bytes >> 20) + " MiB, more than this machine's " +
                        std::to_string(phys >> 20) + " MiB");
}

Volume::Volume(Vec3i dims, VoxelType type, const std::string& where) : m_dims(dims), m_type(type) {
    check_dims(dims, type, where);
    const size_t n = bytes();
    // Zeroed by calloc, not memset: a large calloc is fresh mmap'ed pages that the kernel zeroes
    // when first touched, so a reader that fails early (a tiny .nii.gz claiming 30000^3) costs
    // address space, not memory or time. 64 spare bytes align the data for SIMD row loads.
    void* raw = std::calloc(n + 64, 1);
    if (!raw)
        throw Error(where, "memory", "could not allocate " + std::to_string(n >> 20) + " MiB");
    const uintptr_t aligned = (reinterpret_cast<uintptr_t>(raw) + 63) & ~uintptr_t(63);
    m_owner = std::shared_ptr<void>(raw, [](void* q) { std::free(q); });
    m_data = reinterpret_cast<void*>(aligned);
}

Volume::Volume(Vec3i dims, VoxelType type, std::shared_ptr<void> owner, void* data)
    : m_dims(dims), m_type(type), m_owner(std::move(owner)), m_data(data) {
    check_dims(dims, type, "volume");
}

float Volume::value(int i, int j, int k) const {
    size_t idx = index(i, j, k);
    return visit_voxels(*this, [idx](const auto* p) { return float(p[idx]); });
}

void Volume::set_value(int i, int j, int k, float v) {
    size_t idx = index(i, j, k);
    switch (m_type) {
        case VoxelType::UInt8:
            data_as<uint8_t>()[idx] = uint8_t(v);
            break;
        case VoxelType::Int16:
            data_as<int16_t>()[idx] = int16_t(v);
            break;
        case VoxelType::UInt16:
            data_as<uint16_t>()[idx] = uint16_t(v);
            break;
        case VoxelType::Float32:
            data_as<float>()[idx] = v;
            break;
    }
}

size_t Volume::replace_nan_with_minimum(const std::string& where) {
    if (m_type != VoxelType::Float32) return 0;
    float* p = data_as<float>();
    const size_t n = voxel_count();
    size_t nans = 0;
    float lo = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < n; ++i) {
        if (std::isnan(p[i]))
            ++nans;
        else
            lo = std::min(lo, p[i]);
    }
    if (nans == 0) return 0;
    if (nans == n)
        throw Error(where, "voxel values",
                    "expected at least one voxel that is not NaN, got NaN only");
    // (lo may be -Inf: then compute_range rejects the volume for its Inf, as without NaN.)
    for (size_t i = 0; i < n; ++i)
        if (std::isnan(p[i])) p[i] = lo;
    nan_voxels = nans;
    return nans;
}

void Volume::compute_range(const std::string& where) {
    const size_t n = voxel_count();
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    visit_voxels(*this, [&](const auto* p) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_same_v<T, float>) {
            for (size_t i = 0; i < n; ++i) {
                float v = p[i];
                if (!std::isfinite(v)) {
                    size_t x = i % size_t(m_dims.x), y = (i / size_t(m_dims.x)) % size_t(m_dims.y),
                           z = i / (size_t(m_dims.x) * size_t(m_dims.y));
                    throw Error(where,
                                "voxel (" + std::to_string(x) + "," + std::to_string(y) + "," +
                                    std::to_string(z) + ")",
                                std::string("expected a finite value, found ") +
                                    (std::isnan(v) ? "NaN" : "Inf"));
                }
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        } else {
            T a = p[0], b = p[0];
            for (size_t i = 0; i < n; ++i) {
                a = std::min(a, p[i]);
                b = std::max(b, p[i]);
            }
            lo = float(a);
            hi = float(b);
        }
    });
    // Float voxels spread wider than float (e.g. -3e38 and 3e38): a trilinear lerp of two of
    // them computes b - a = inf and then inf * 0 or inf - inf, a NaN sample. Rejected, like
    // non-finite voxels (the totality argument of ValueToLut, transfer_function.h).
    if (!std::isfinite(hi - lo))
        throw Error(where, "voxel values",
                    "expected max - min within float (3.4e38), got " + std::to_string(lo) + " .. " +
                        std::to_string(hi));
    // Float voxels within an ulp of float's end (fuzz_value_to_lut: corners 1.16e38 and 3.4e38):
    // a trilinear lerp a + f * (b - a) can round one ulp past its corners, which at 3.4e38 is
    // inf. Below 2^127 (1.7e38) three lerps' ulps cannot reach 2^128. Equal corners lerp
    // exactly, so a constant volume is kept.
    if (m_type == VoxelType::Float32 && lo != hi && std::max(-lo, hi) > 0x1p127f)
        throw Error(where, "voxel values",
                    "expected values within +-1.7e38 (a trilinear sample rounds up to an ulp past "
                    "its corners, and float ends at 3.4e38), got " +
                        std::to_string(lo) + " .. " + std::to_string(hi));
    m_data_range = {lo, hi};
    if (!m_vis_set) {
        m_vis_range = m_data_range;
        // A constant volume, or one narrower than the LUT's float scale resolves (values within
        // ~3e-36 of each other, e.g. a NIfTI scl_slope of 1e-40), still needs a usable range:
        // [min, min + 1], or one step of float wider where min + 1 rounds to min.
        if (!lut_range_ok(m_vis_range)) {
            constexpr float inf = std::numeric_limits<float>::infinity();
            m_vis_range.max = std::max(lo + 1.f, std::nextafter(lo, inf));
            if (!std::isfinite(m_vis_range.max)) m_vis_range = {std::nextafter(lo, -inf), lo};
        }
    }
}

void Volume::set_vis_range(ValueRange r) {
    check_lut_range(r, kDefaultLutSize, "volume", "vis_range");
    m_vis_range = r;
    m_vis_set = true;
}

Vec3f Volume::world_extent() const {
    return Vec3f{float((m_dims.x - 1) * spacing.x), float((m_dims.y - 1) * spacing.y),
                 float((m_dims.z - 1) * spacing.z)};
}

std::string to_string(const Volume& v) {
    auto d = v.dims();
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z) + " " +
           to_string(v.type()) + " spacing " + to_string(v.spacing) + " range [" +
           std::to_string(v.data_range().min) + ", " + std::to_string(v.data_range().max) + "]";
}

}  // namespace lacuna
