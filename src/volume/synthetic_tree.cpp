// SyntheticKind::Tree: a plant like the kd-tree paper's models A, C and E (Section 3): a trunk,
// recursively branching limbs and clusters of leaves, with most of the box empty.
#include <algorithm>
#include <cmath>

#include "volume/synthetic_detail.h"

namespace lacuna::synthetic_detail {

namespace {

// Tree space: the trunk starts at the origin and grows along +z; the crown fits roughly in
// [-0.5,0.5]^2 x [0,1]. One tree unit is (min(dims) - 1) voxels for radii; positions map
// per axis (tree_to_index) so the tree fills non-cubic boxes too.
constexpr int kTrunkSegments = 6;
constexpr int kBranchSegments = 4;
constexpr double kTrunkLength = 0.38;
constexpr double kTrunkRadius = 0.028;
constexpr double kTaper = 0.6;         // radius at a branch's end / at its start
constexpr double kChildRadius = 0.75;  // child's start radius / parent's radius at the fork
constexpr double kWiggle = 0.22;       // random bend per segment (length of a random vector)
constexpr double kTropism = 0.12;      // upward pull per segment
constexpr double kTargetTips = 180;    // about this many branch ends, whatever the depth
// Thinnest rendered radius in voxels: below ~1 voxel a twig would fall between samples.
constexpr double kMinWoodVoxels = 1.0;
constexpr double kMinLeafVoxels = 1.2;

struct TreeBuilder {
    Rng rng;
    Vec3i dims;
    Vec3d origin;         // index position of the trunk base
    Vec3d scale;          // index units per tree unit, per axis
    double radius_scale;  // voxels per tree unit for radii
    int levels;
    double mean_children;
    std::vector<Capsule> caps;

    Vec3d to_index(Vec3d p) const { return origin + p * scale; }

    void add(Vec3d a, Vec3d b, double ra, double rb, float value, double min_voxels) {
        Capsule c;
        c.a = to_index(a);
        c.b = to_index(b);
        c.ra = std::max(ra * radius_scale, min_voxels);
        c.rb = std::max(rb * radius_scale, min_voxels);
        c.value = value;
        caps.push_back(c);
    }

    // A direction at roughly atan(0.35..1.2) = 20..50 degrees from `d`, around it at random.
    Vec3d fork_direction(Vec3d d) {
        Vec3d perp;
        for (;;) {
            Vec3d v = rng.unit_vector();
            perp = v - d * dot(v, d);
            if (dot(perp, perp) > 1e-3) break;
        }
        return normalize(d + normalize(perp) * rng.uniform(0.35, 1.2));
    }

    void leaves(Vec3d tip, int level) {
        const int n = rng.integer(4, 7);
        const double spread = 0.045;
        for (int i = 0; i < n; ++i) {
            Vec3d p = tip + rng.unit_vector() * (spread * rng.uniform());
            double r = rng.uniform(0.014, 0.024) * (level >= 5 ? 0.8 : 1.0);
            float value = float(rng.uniform(0.35, 0.55));
            add(p, p, r, r, value, kMinLeafVoxels);
        }
    }

    // Grows one limb of `segments` bent segments, then its children (or leaves at the top).
    void branch(Vec3d start, Vec3d dir, double length, double radius, int level) {
        const int segments = level == 0 ? kTrunkSegments : kBranchSegments;
        const float wood = level == 0 ? 1.f : float(0.95 - 0.04 * level);
        std::vector<Vec3d> points{start};
        std::vector<double> radii{radius};
        Vec3d p = start, d = dir;
        for (int s = 1; s <= segments; ++s) {
            // The trunk's first segment stays exactly vertical from a voxel-aligned base, so
            // its axis passes through voxel centres and the volume reaches s = 1 exactly.
            if (!(level == 0 && s == 1))
                d = normalize(d + rng.unit_vector() * kWiggle + Vec3d{0, 0, kTropism});
            Vec3d q = p + d * (length / segments);
            double r = radius * (1.0 - (1.0 - kTaper) * double(s) / segments);
            add(p, q, radii.back(), r, wood, kMinWoodVoxels);
            points.push_back(q);
            radii.push_back(r);
            p = q;
        }
        if (level + 1 >= levels) {
            leaves(points[segments / 2], level);
            leaves(p, level);
            return;
        }
        const int children = std::max(2, int(mean_children + rng.uniform()));
        for (int c = 0; c < children; ++c) {
            // The first child continues from the tip; the others fork off the upper half.
            const int at = c == 0 ? segments : rng.integer(segments / 2, segments);
            const Vec3d fork = c == 0 ? normalize(d + rng.unit_vector() * 0.3) : fork_direction(d);
            const double len = length * rng.uniform(0.6, 0.8);
            branch(points[at], fork, len, radii[at] * kChildRadius, level + 1);
        }
    }
};

}  // namespace

std::vector<Capsule> build_tree(Vec3i dims, uint32_t seed) {
    TreeBuilder t{make_rng(SyntheticKind::Tree, seed), dims, {}, {}, 0, 0, 0, {}};
    t.origin = {std::floor((dims.x - 1) / 2.0), std::floor((dims.y - 1) / 2.0), 0.0};
    t.scale = {double(dims.x - 1), double(dims.y - 1), double(dims.z - 1)};
    t.radius_scale = double(std::min({dims.x, dims.y, dims.z}) - 1);
    t.levels = t.rng.integer(3, 6);
    // levels-1 forking generations of about mean_children each give ~kTargetTips ends.
    t.mean_children = std::pow(kTargetTips, 1.0 / (t.levels - 1));
    t.mean_children = std::min(t.mean_children, 6.0);
    Vec3d up{0, 0, 1};
    t.branch({0, 0, 0}, up, kTrunkLength, kTrunkRadius, 0);
    return t.caps;
}

void rasterise_capsules(const std::vector<Capsule>& caps, Vec3i dims, int k, float* slice) {
    const double z = k;
    for (const Capsule& c : caps) {
        const double rmax = std::max(c.ra, c.rb);
        const Vec3d ab = c.b - c.a;
        // Segment parameters whose points lie within rmax of the plane z = k.
        double t0 = 0, t1 = 1;
        if (std::abs(ab.z) > 1e-12) {
            t0 = (z - rmax - c.a.z) / ab.z;
            t1 = (z + rmax - c.a.z) / ab.z;
            if (t0 > t1) std::swap(t0, t1);
            t0 = std::max(t0, 0.0);
            t1 = std::min(t1, 1.0);
            if (t0 > t1) continue;
        } else if (std::abs(c.a.z - z) > rmax) {
            continue;
        }
        const Vec3d p0 = c.a + ab * t0, p1 = c.a + ab * t1;
        const int x0 = std::max(0, int(std::ceil(std::min(p0.x, p1.x) - rmax)));
        const int x1 = std::min(dims.x - 1, int(std::floor(std::max(p0.x, p1.x) + rmax)));
        const int y0 = std::max(0, int(std::ceil(std::min(p0.y, p1.y) - rmax)));
        const int y1 = std::min(dims.y - 1, int(std::floor(std::max(p0.y, p1.y) + rmax)));
        const double len2 = dot(ab, ab);
        const double inv_len2 = len2 > 0 ? 1.0 / len2 : 0.0;
        for (int j = y0; j <= y1; ++j) {
            float* row = slice + size_t(j) * size_t(dims.x);
            for (int i = x0; i <= x1; ++i) {
                // Closest point on the axis, the radius there, then the smooth profile.
                const Vec3d ap = Vec3d{double(i), double(j), z} - c.a;
                const double t = std::clamp(dot(ap, ab) * inv_len2, 0.0, 1.0);
                const Vec3d q = ap - ab * t;
                const double d2 = dot(q, q);
                const double r = c.ra + t * (c.rb - c.ra);
                if (d2 >= r * r) continue;
                const double w = std::min(1.0, (r - std::sqrt(d2)) / (0.5 * r));
                const float v = float(double(c.value) * w * w * (3.0 - 2.0 * w));
                row[i] = std::max(row[i], v);
            }
        }
    }
}

}  // namespace lacuna::synthetic_detail
