#include "lacuna/synthetic.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "lacuna/error.h"
#include "volume/synthetic_detail.h"

namespace lacuna {

using namespace synthetic_detail;

namespace {

struct KindName {
    SyntheticKind kind;
    const char* name;
};
constexpr std::array<KindName, 9> kKindNames{{
    {SyntheticKind::SphereShells, "sphere-shells"},
    {SyntheticKind::MarschnerLobb, "marschner-lobb"},
    {SyntheticKind::Tree, "tree"},
    {SyntheticKind::NoiseBlobs, "noise-blobs"},
    {SyntheticKind::ThinSheets, "thin-sheets"},
    {SyntheticKind::Checkerboard, "checkerboard"},
    {SyntheticKind::BinBoundaries, "bin-boundaries"},
    {SyntheticKind::Slab, "slab"},
    {SyntheticKind::Sphere, "sphere"},
}};

Vec3d centre_of(Vec3i d) {
    return Vec3d{d.x - 1.0, d.y - 1.0, d.z - 1.0} * 0.5;
}
int min_extent(Vec3i d) {
    return std::min({d.x, d.y, d.z}) - 1;
}

// Fills every voxel with q(signal(i, j, k)).
template <class T, class Signal>
void fill_signal(Volume& vol, int threads, Signal&& signal) {
    const Vec3i d = vol.dims();
    const Quantiser<T> q(vol.type());
    for_each_slice<T>(vol, threads, [&](int k, T* slice, std::vector<float>&) {
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) slice[size_t(j) * d.x + i] = q(signal(i, j, k));
    });
}

// Fills every slice by raster(k, float* s) into a zeroed nx*ny float buffer, then quantises it.
template <class T, class Raster>
void fill_rasterised(Volume& vol, int threads, Raster&& raster) {
    const Vec3i d = vol.dims();
    const size_t n = size_t(d.x) * size_t(d.y);
    const Quantiser<T> q(vol.type());
    for_each_slice<T>(vol, threads, [&](int k, T* slice, std::vector<float>& s) {
        s.assign(n, 0.f);
        raster(k, s.data());
        for (size_t i = 0; i < n; ++i) slice[i] = q(s[i]);
    });
}

template <class T>
void generate_sphere_shells(Volume& vol, int threads) {
    struct Shell {
        double inner, outer;
        float value;
    };
    static constexpr Shell kShells[] = {
        {0.15, 0.30, 1.f}, {0.40, 0.55, 0.75f}, {0.65, 0.75, 0.5f}, {0.85, 0.95, 0.25f}};
    const Vec3d c = centre_of(vol.dims());
    const double radius = 0.5 * min_extent(vol.dims());
    fill_signal<T>(vol, threads, [&](int i, int j, int k) {
        const Vec3d p{i - c.x, j - c.y, k - c.z};
        const double rho = std::sqrt(dot(p, p)) / radius;
        for (const Shell& s : kShells)
            if (rho >= s.inner && rho <= s.outer) return s.value;
        return 0.f;
    });
}

// The Marschner-Lobb signal split into its z term and its radial term, so the generator can
// compute each once per slice / per column and still match marschner_lobb() bit for bit.
constexpr double kMlAlpha = 0.25, kMlFm = 6.0;
double ml_z_term(float z) {
    return 1.0 - std::sin(std::numbers::pi * double(z) / 2.0);
}
double ml_radial_term(float x, float y) {
    const double r = std::sqrt(double(x) * x + double(y) * y);
    return kMlAlpha *
           (1.0 + std::cos(2.0 * std::numbers::pi * kMlFm * std::cos(std::numbers::pi * r / 2.0)));
}
float ml_combine(double z_term, double radial_term) {
    return float((z_term + radial_term) / (2.0 * (1.0 + kMlAlpha)));
}
float ml_coord(int i, int n) {
    return -1.f + 2.f * float(i) / float(n - 1);
}

template <class T>
void generate_marschner_lobb(Volume& vol, int threads) {
    const Vec3i d = vol.dims();
    std::vector<double> radial(size_t(d.x) * d.y);
    for (int j = 0; j < d.y; ++j)
        for (int i = 0; i < d.x; ++i)
            radial[size_t(j) * d.x + i] = ml_radial_term(ml_coord(i, d.x), ml_coord(j, d.y));
    const Quantiser<T> q(vol.type());
    for_each_slice<T>(vol, threads, [&](int k, T* slice, std::vector<float>&) {
        const double zt = ml_z_term(ml_coord(k, d.z));
        for (size_t n = 0; n < radial.size(); ++n) slice[n] = q(ml_combine(zt, radial[n]));
    });
}

template <class T>
void generate_tree(Volume& vol, int threads, uint32_t seed) {
    const std::vector<Capsule> caps = build_tree(vol.dims(), seed);
    fill_rasterised<T>(vol, threads,
                       [&](int k, float* s) { rasterise_capsules(caps, vol.dims(), k, s); });
}

// Gaussians truncated at 3 sigma and shifted so they reach exactly 0 there:
//     g(d) = (exp(-d^2 / (2 sigma^2)) - exp(-4.5)) / (1 - exp(-4.5)),  d < 3 sigma
// Blob 0 sits on the voxel nearest the centre with amplitude 1, so the maximum is exactly 1;
// the others are centred in the middle 60% of each axis, so the corners are always empty.
template <class T>
void generate_noise_blobs(Volume& vol, int threads, uint32_t seed) {
    struct Blob {
        Vec3d c;
        double sigma, amplitude;
    };
    const Vec3i d = vol.dims();
    const double m = min_extent(d);
    Rng rng = make_rng(SyntheticKind::NoiseBlobs, seed);
    const Vec3d c = centre_of(d);
    std::vector<Blob> blobs(size_t(rng.integer(24, 40)));
    for (size_t b = 0; b < blobs.size(); ++b) {
        Blob& bl = blobs[b];
        bl.c = b == 0 ? Vec3d{std::round(c.x), std::round(c.y), std::round(c.z)}
                      : Vec3d{rng.uniform(0.2, 0.8) * (d.x - 1), rng.uniform(0.2, 0.8) * (d.y - 1),
                              rng.uniform(0.2, 0.8) * (d.z - 1)};
        bl.sigma = std::max(0.5, rng.uniform(0.02, 0.05) * m);
        bl.amplitude = b == 0 ? 1.0 : rng.uniform(0.3, 1.0);
    }
    const double tail = std::exp(-4.5);
    fill_rasterised<T>(vol, threads, [&](int k, float* s) {
        // Sums in blob order for every voxel, so the float sums are the same on any schedule.
        for (const Blob& b : blobs) {
            const double cut = 3.0 * b.sigma, dz = k - b.c.z;
            if (std::abs(dz) >= cut) continue;
            const double disc = std::sqrt(cut * cut - dz * dz);
            const int x0 = std::max(0, int(std::ceil(b.c.x - disc)));
            const int x1 = std::min(d.x - 1, int(std::floor(b.c.x + disc)));
            const int y0 = std::max(0, int(std::ceil(b.c.y - disc)));
            const int y1 = std::min(d.y - 1, int(std::floor(b.c.y + disc)));
            const double inv = 1.0 / (2.0 * b.sigma * b.sigma);
            for (int j = y0; j <= y1; ++j)
                for (int i = x0; i <= x1; ++i) {
                    const double d2 =
                        (i - b.c.x) * (i - b.c.x) + (j - b.c.y) * (j - b.c.y) + dz * dz;
                    if (d2 >= cut * cut) continue;
                    const double g = (std::exp(-d2 * inv) - tail) / (1.0 - tail);
                    s[size_t(j) * d.x + i] += float(b.amplitude * g);
                }
        }
    });
}

template <class T>
void generate_thin_sheets(Volume& vol, int threads) {
    const Vec3i d = vol.dims();
    const int px = d.x / 3, py = d.y / 2, pz = 2 * d.z / 3, diag = (d.x + d.y + d.z - 3) / 2;
    fill_signal<T>(vol, threads, [&](int i, int j, int k) {
        const bool on = i == px || j == py || k == pz || i == j || i + j + k == diag;
        return on ? 1.f : 0.f;
    });
}

template <class T>
void generate_checkerboard(Volume& vol, int threads) {
    fill_signal<T>(vol, threads, [](int i, int j, int k) { return ((i + j + k) & 1) ? 1.f : 0.f; });
}

template <class T>
void generate_slab(Volume& vol, int threads) {
    const int z0 = vol.dims().z / 4, z1 = 3 * vol.dims().z / 4;
    fill_signal<T>(vol, threads, [=](int, int, int k) { return k >= z0 && k <= z1 ? 1.f : 0.f; });
}

template <class T>
void generate_sphere(Volume& vol, int threads) {
    const Vec3d c = centre_of(vol.dims());
    const double r = 0.35 * min_extent(vol.dims());
    fill_signal<T>(vol, threads, [&](int i, int j, int k) {
        const double d2 = (i - c.x) * (i - c.x) + (j - c.y) * (j - c.y) + (k - c.z) * (k - c.z);
        return d2 <= r * r ? 1.f : 0.f;
    });
}

// Stored values that sit on, or one quantum either side of, the places where value -> bin maps
// change their answer, over the data range [lo, hi] = synthetic_value_range (w = hi - lo):
//   - bitfield bins: B equal bins over the range, B in {8, 16, 32, 64, 128} (bitfield paper,
//     Section 3.1); the boundaries lo + k w / B are all among lo + k w / 128.
//   - LUT entries (transfer_function.h, 1024 entries): entry e covers values rounding to
//     u = (v - lo) * 1023 / w in [e - 0.5, e + 0.5): boundaries lo + (e - 0.5) w / 1023.
//   - plain 1024ths, lo + k w / 1024, for structures that bin by 1024 equal slots.
// Integer types store round(boundary) - 1, round(boundary), round(boundary) + 1 (so the two
// values bracketing a fractional boundary are both present); float32 stores the boundary and
// its float neighbours. 0 (empty) and the max come first so every volume spans [lo, hi].
template <class T>
std::vector<T> bin_boundary_values(VoxelType type) {
    const ValueRange range = synthetic_value_range(type);
    const double lo = range.min, hi = range.max, w = hi - lo;
    std::vector<T> out{T(lo), T(hi)};
    auto add = [&](double boundary) {
        if constexpr (std::is_same_v<T, float>) {
            const float b = float(boundary);
            for (float v : {std::nextafter(b, -1.f), b, std::nextafter(b, 2.f)})
                out.push_back(std::clamp(v, float(lo), float(hi)));
        } else {
            const double b = std::round(boundary);
            for (double v : {b - 1, b, b + 1}) out.push_back(T(std::clamp(v, lo, hi)));
        }
    };
    for (int bins : {8, 16, 32, 64, 128})
        for (int k = 1; k < bins; ++k)
            if (bins == 8 || k % 2 == 1) add(lo + k * w / bins);  // each boundary once
    for (int e = 1; e < 1024; ++e) add(lo + (e - 0.5) * w / 1023);
    for (int k = 1; k < 1024; ++k) add(lo + k * w / 1024);
    return out;
}

// 2x2x2-voxel bricks, each one constant value from bin_boundary_values in order along x, then
// y, then z, so the cells between neighbouring bricks span a boundary and its neighbour; every
// brick with (bi + bj + bk) % 4 == 3 stays empty.
template <class T>
void generate_bin_boundaries(Volume& vol, int threads) {
    const std::vector<T> values = bin_boundary_values<T>(vol.type());
    const Vec3i d = vol.dims();
    const size_t bx = size_t(d.x + 1) / 2, by = size_t(d.y + 1) / 2;
    const T empty = T(synthetic_value_range(vol.type()).min);
    for_each_slice<T>(vol, threads, [&](int k, T* slice, std::vector<float>&) {
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const size_t bi = size_t(i) / 2, bj = size_t(j) / 2, bk = size_t(k) / 2;
                const size_t brick = (bk * by + bj) * bx + bi;
                const bool hole = (bi + bj + bk) % 4 == 3;
                slice[size_t(j) * d.x + i] = hole ? empty : values[brick % values.size()];
            }
    });
}

template <class T>
void generate_typed(SyntheticKind kind, const SyntheticOptions& o, Volume& vol) {
    switch (kind) {
        case SyntheticKind::SphereShells:
            generate_sphere_shells<T>(vol, o.threads);
            break;
        case SyntheticKind::MarschnerLobb:
            generate_marschner_lobb<T>(vol, o.threads);
            break;
        case SyntheticKind::Tree:
            generate_tree<T>(vol, o.threads, o.seed);
            break;
        case SyntheticKind::NoiseBlobs:
            generate_noise_blobs<T>(vol, o.threads, o.seed);
            break;
        case SyntheticKind::ThinSheets:
            generate_thin_sheets<T>(vol, o.threads);
            break;
        case SyntheticKind::Checkerboard:
            generate_checkerboard<T>(vol, o.threads);
            break;
        case SyntheticKind::BinBoundaries:
            generate_bin_boundaries<T>(vol, o.threads);
            break;
        case SyntheticKind::Slab:
            generate_slab<T>(vol, o.threads);
            break;
        case SyntheticKind::Sphere:
            generate_sphere<T>(vol, o.threads);
            break;
    }
}

}  // namespace

std::string to_string(SyntheticKind k) {
    for (const KindName& kn : kKindNames)
        if (kn.kind == k) return kn.name;
    return "?";
}

std::vector<std::string> synthetic_kind_names() {
    std::vector<std::string> names;
    for (const KindName& kn : kKindNames) names.emplace_back(kn.name);
    return names;
}

SyntheticKind parse_synthetic_kind(const std::string& name) {
    std::string list;
    for (const KindName& kn : kKindNames) {
        if (name == kn.name) return kn.kind;
        list += (list.empty() ? "" : ", ") + std::string(kn.name);
    }
    throw Error("generate", "kind", "unknown '" + name + "'; expected one of: " + list);
}

ValueRange synthetic_value_range(VoxelType t) {
    switch (t) {
        case VoxelType::UInt8:
            return {0.f, 255.f};
        case VoxelType::Int16:
            return {-1024.f, 3071.f};
        case VoxelType::UInt16:
            return {0.f, 65535.f};
        case VoxelType::Float32:
            return {0.f, 1.f};
    }
    return {0.f, 1.f};
}

float marschner_lobb(float x, float y, float z) {
    return ml_combine(ml_z_term(z), ml_radial_term(x, y));
}

Volume generate(SyntheticKind kind, const SyntheticOptions& opts) {
    Volume vol(opts.dims, opts.type, "generate " + to_string(kind));
    with_voxel_type(opts.type, [&](auto tag) { generate_typed<decltype(tag)>(kind, opts, vol); });
    vol.compute_range("generate " + to_string(kind));
    return vol;
}

}  // namespace lacuna
