// Private helpers of the synthetic volume generators (src/volume/synthetic*.cpp): a portable
// random stream, the [0,1] -> voxel quantiser, the slice-parallel fill loop and the capsule
// rasteriser shared by Tree and NoiseBlobs.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/parallel.h"
#include "lacuna/synthetic.h"
#include "lacuna/volume.h"

namespace lacuna::synthetic_detail {

// splitmix64 (Steele, Lea & Flood 2014): fixed integer arithmetic, so the same stream on every
// platform and standard library, unlike std::*_distribution.
class Rng {
  public:
    explicit Rng(uint64_t seed) : m_state(seed) {}
    uint64_t next() {
        uint64_t z = (m_state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    // Uniform in [0,1): the top 53 bits, exact in double.
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    // Uniform integer in [lo, hi] (modulo bias is irrelevant for these tiny ranges).
    int integer(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); }
    // Uniform direction: rejection in the cube, so only +,*,sqrt (bit-exact everywhere).
    Vec3d unit_vector() {
        for (;;) {
            Vec3d v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
            double l2 = dot(v, v);
            if (l2 > 1e-4 && l2 <= 1.0) return v / std::sqrt(l2);
        }
    }

  private:
    uint64_t m_state;
};

// Stream for one (kind, seed): the kind salts the seed so kinds never share numbers.
inline Rng make_rng(SyntheticKind kind, uint32_t seed) {
    Rng mix((uint64_t(seed) << 8) ^ uint64_t(kind));
    mix.next();
    return Rng(mix.next());
}

// Maps the normalised signal s in [0,1] to stored values lo + round(s * (hi - lo)).
// Monotone, so max(q(a), q(b)) == q(max(a, b)).
template <class T>
struct Quantiser {
    double lo, width;
    explicit Quantiser(VoxelType t) {
        ValueRange r = synthetic_value_range(t);
        lo = r.min;
        width = double(r.max) - double(r.min);
    }
    T operator()(float s) const {
        s = s < 0.f ? 0.f : (s > 1.f ? 1.f : s);
        if constexpr (std::is_same_v<T, float>) {
            return s;
        } else {
            return T(lo + std::floor(double(s) * width + 0.5));
        }
    }
};

// Calls f(T{}) with the volume's voxel type (mutable counterpart of visit_voxels).
template <class F>
void with_voxel_type(VoxelType t, F&& f) {
    switch (t) {
        case VoxelType::UInt8:
            f(uint8_t{});
            break;
        case VoxelType::Int16:
            f(int16_t{});
            break;
        case VoxelType::UInt16:
            f(uint16_t{});
            break;
        case VoxelType::Float32:
            f(float{});
            break;
    }
}

// Calls fn(k, slice, scratch) for every z slice k, in parallel over slices. slice points at the
// nx*ny voxels of slice k (x fastest); scratch is a per-chunk buffer fn may resize and reuse.
// Each slice is written by exactly one call, so the result never depends on the thread count.
template <class T, class Fn>
void for_each_slice(Volume& vol, int threads, Fn&& fn) {
    const Vec3i d = vol.dims();
    const size_t slice_size = size_t(d.x) * size_t(d.y);
    T* data = vol.data_as<T>();
    parallel_for(size_t(d.z), threads, [&](size_t k0, size_t k1) {
        std::vector<float> scratch;
        for (size_t k = k0; k < k1; ++k) fn(int(k), data + k * slice_size, scratch);
    });
}

// A tapered capsule in index space: the points within r(t) = ra + t (rb - ra) of the point at
// parameter t on the segment a->b, t being the closest-point parameter. a == b gives a ball.
// Density value * smoothstep((r - dist) / (r/2)): `value` on the inner half of the radius,
// falling smoothly to exactly 0 at the surface.
struct Capsule {
    Vec3d a, b;
    double ra = 1, rb = 1;
    float value = 1;
};

// Max-combines every capsule touching slice k into `slice` (nx*ny floats, x fastest).
// Only the capsule's footprint on the slice is visited: the part of the segment within
// max(ra,rb) of the plane z = k, grown by that radius in x and y.
void rasterise_capsules(const std::vector<Capsule>& caps, Vec3i dims, int k, float* slice);

// Capsules of a tree built from the seed, in index space for `dims` (synthetic_tree.cpp).
std::vector<Capsule> build_tree(Vec3i dims, uint32_t seed);

}  // namespace lacuna::synthetic_detail
