// Random volumes, TFs and cameras for the conformance suites (skipping_conformance_test.cpp,
// feature_conformance_test.cpp) and the render tests: sparse random voxels, single-entry opacity
// spikes, cameras inside and outside the volume.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/rng.h"
#include "core/simd_lanes.h"
#include "lacuna/camera.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::test {

// A LUT that is transparent except for one entry (the sharpest test of a structure).
inline TransferLut spike_lut(ValueRange vis, int entry, float opacity = 0.7f) {
    TransferLut lut;
    lut.vis = vis;
    lut.entries.assign(kDefaultLutSize, Rgba{});
    lut.entries[size_t(std::clamp(entry, 0, kDefaultLutSize - 1))] = {0.9f, 0.6f, 0.3f, opacity};
    return lut;
}

// A random piecewise TF: a few random opacity bumps with zero between them.
inline TransferLut random_lut(ValueRange vis, Rng& rng) {
    TransferLut lut;
    lut.vis = vis;
    lut.entries.assign(kDefaultLutSize, Rgba{});
    const int bumps = rng.range(1, 4);
    for (int b = 0; b < bumps; ++b) {
        const int c = rng.range(0, kDefaultLutSize - 1), w = rng.range(0, 40);
        const float a = 0.05f + 0.9f * rng.uniform();
        for (int e = std::max(0, c - w); e <= std::min(kDefaultLutSize - 1, c + w); ++e)
            lut.entries[size_t(e)] = {rng.uniform(), rng.uniform(), rng.uniform(), a};
    }
    return lut;
}

inline Camera random_camera(const Volume& v, Rng& rng, int size) {
    OrbitParams p;
    p.azimuth_deg = 360.f * rng.uniform();
    p.elevation_deg = -80.f + 160.f * rng.uniform();
    p.projection = rng.range(0, 3) == 0 ? Projection::Orthographic : Projection::Perspective;
    const Box3f b{{0, 0, 0}, v.world_extent()};
    if (p.projection == Projection::Perspective && rng.range(0, 2) == 0) {
        p.has_target = true;
        p.target = {b.hi.x * rng.uniform(), b.hi.y * rng.uniform(), b.hi.z * rng.uniform()};
        p.distance = 0.05f + 0.3f * length(b.extent()) * rng.uniform();
        p.fov_y_deg = 40.f + 60.f * rng.uniform();
    } else {
        p.zoom = 0.7f + 2.f * rng.uniform();
    }
    return Camera::orbit(b, p, size, size);
}

// Sparse random content plus a few solid blobs (so gradients and shadows have surfaces).
inline Volume random_volume(Rng& rng, int max_dim) {
    const Vec3i dims{rng.range(2, max_dim), rng.range(2, max_dim), rng.range(2, max_dim)};
    const VoxelType type = VoxelType(rng.range(0, 3));
    Volume v(dims, type);
    const float hi = type == VoxelType::UInt8 ? 255.f : (type == VoxelType::Float32 ? 1.f : 4000.f);
    auto value = [&] {
        return type == VoxelType::Float32 ? hi * rng.uniform() : std::floor(hi * rng.uniform());
    };
    const int points = rng.range(1, 60);
    for (int p = 0; p < points; ++p)
        v.set_value(rng.range(0, dims.x - 1), rng.range(0, dims.y - 1), rng.range(0, dims.z - 1),
                    value());
    const int blobs = rng.range(0, 3);
    for (int b = 0; b < blobs; ++b) {
        const int cx = rng.range(0, dims.x - 1), cy = rng.range(0, dims.y - 1),
                  cz = rng.range(0, dims.z - 1);
        const int r = rng.range(1, 4);
        const float val = value();
        for (int z = std::max(0, cz - r); z <= std::min(dims.z - 1, cz + r); ++z)
            for (int y = std::max(0, cy - r); y <= std::min(dims.y - 1, cy + r); ++y)
                for (int x = std::max(0, cx - r); x <= std::min(dims.x - 1, cx + r); ++x)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= r * r)
                        v.set_value(x, y, z, val);
    }
    v.set_value(0, 0, 0, hi);  // a known range
    v.compute_range();
    return v;
}

// A dense LUT of `entries` entries, every one different (a third transparent): an interpolated
// value one ulp off usually lands in another entry, so a kernel path that rounds differently
// shows in the image.
inline void make_dense(TransferLut& lut, size_t entries, Rng& rng) {
    lut.entries.resize(entries);
    for (Rgba& e : lut.entries)
        e = {rng.uniform(), rng.uniform(), rng.uniform(), rng.coin(3) ? 0.f : rng.uniform()};
}

// Every kernel path this CPU runs (core/simd_lanes.h), narrowest (scalar) first; the active path
// is restored when this goes out of scope.
struct KernelPaths {
    std::vector<simd::Isa> paths;
    simd::Isa saved = simd::active_isa();
    KernelPaths() {
        for (simd::Isa i :
             {simd::Isa::Scalar, simd::Isa::Sse41, simd::Isa::Avx2, simd::Isa::Avx512})
            if (simd::isa_supported(i)) paths.push_back(i);
    }
    ~KernelPaths() { simd::set_isa(saved); }
};

}  // namespace lacuna::test
