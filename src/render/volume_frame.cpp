#include "render/volume_frame.h"

#include <algorithm>

namespace lacuna {

FeatureOptions to_volume_frame(const VolumeFrame& f, const FeatureOptions& world) {
    if (f.identity) return world;
    FeatureOptions v = world;
    // dot(n, p) >= d with p = R q + from  <=>  dot(R^T n, q) >= d - dot(n, from).
    auto plane = [&](Vec3f n, double d) {
        const double nf = double(n.x) * f.from.x + double(n.y) * f.from.y + double(n.z) * f.from.z;
        return ClipPlane{f.vector(n), float(d - nf)};
    };
    for (ClipPlane& c : v.clip_planes) c = plane(c.normal, c.d);
    if (world.crop) {
        const Box3f& b = world.crop_box;
        if (f.axis_aligned()) {
            const Vec3f p = f.point(b.lo), q = f.point(b.hi);
            v.crop_box = {vmin(p, q), vmax(p, q)};
        } else {
            v.crop = false;
            for (int a = 0; a < 3; ++a) {
                Vec3f n{0, 0, 0};
                n[a] = 1.f;
                v.clip_planes.push_back(plane(n, b.lo[a]));  // x_a >= lo
                n[a] = -1.f;
                v.clip_planes.push_back(plane(n, -b.hi[a]));  // x_a <= hi
            }
        }
    }
    v.light.direction = f.vector(world.light.direction);
    v.light.position = f.point(world.light.position);
    v.light.target = f.point(world.light.target);
    return v;
}

}  // namespace lacuna
