// Distributed rendering in one process (no MPI): every brick of a decomposition rendered through
// its own brick session (Session::set_brick), the partials composited in the kd-tree's visibility
// order (dist/composite.h), against the single-process frame with early termination off. What
// mpirun adds on top (messages) is tested by tests/dist/mpi/.
#include <gtest/gtest.h>

#include <cstring>

#include "conformance/conformance_util.h"
#include "dist/brick_io.h"
#include "dist/composite.h"
#include "dist/decomposition.h"
#include "lacuna/accel.h"
#include "lacuna/orientation.h"
#include "lacuna/session.h"
#include "lacuna/synthetic.h"
#include "render/pixel_driver.h"

namespace lacuna::dist {
namespace {

TransferFunction test_tf() {
    TransferFunction tf;
    tf.name = "test";
    tf.color = {{0.0, 0.9f, 0.3f, 0.1f}, {0.5, 0.2f, 0.8f, 0.4f}, {1.0, 1.f, 1.f, 0.9f}};
    tf.opacity = {{0.0, 0.f}, {0.2, 0.f}, {0.45, 0.3f}, {0.7, 0.05f}, {1.0, 0.8f}};
    return tf;
}

struct Bricked {
    Image image;
    std::vector<uint32_t> counts;  // per pixel, summed over the bricks
};

// The frame from `n` brick sessions composited front to back on the pixels' float RGBA.
Bricked render_bricked(const Volume& whole, const TransferFunction& tf, const FrameSpec& spec,
                       int n, Balance balance) {
    const Decomposition d = balance == Balance::Voxels
                                ? decompose_voxels(whole.dims(), n)
                                : decompose_visible(whole, discretise(tf, whole.vis_range()), n, 1);
    std::vector<Partial> parts;
    Bricked out;
    out.counts.assign(size_t(spec.width) * spec.height, 0);
    Vec3f eye, dir;
    bool ortho = false;
    for (int r = 0; r < n; ++r) {
        const BrickOwnership own = ownership(d, r);
        Session s(crop_brick(whole, own.offset, brick_voxels(d, r)), 1);
        s.set_brick(own, world_bounds(whole));
        s.set_transfer_function(tf);
        FrameSpec f = spec;
        f.keep_float = true;
        f.count_samples = true;
        FrameResult fr = s.render(f);
        for (size_t p = 0; p < out.counts.size(); ++p) out.counts[p] += fr.sample_counts[p];
        parts.push_back({spec.width, spec.height, std::move(fr.rgba_float)});
        const Camera cam = to_volume_frame(volume_frame(s.volume()), s.camera(f));
        const Vec3d sp = s.volume().spacing;
        const Vec3f inv{float(1 / sp.x), float(1 / sp.y), float(1 / sp.z)};
        eye = cam.eye() * inv, dir = cam.forward() * inv;
        ortho = cam.projection() == Projection::Orthographic;
    }
    Partial acc{spec.width, spec.height,
                std::vector<float>(size_t(spec.width) * spec.height * 4, 0.f)};
    const Rect whole_rect{0, 0, spec.width, spec.height};
    for (int r : visibility_order(d, eye, dir, ortho)) {
        const Rect rect = nonempty_rect(parts[size_t(r)], whole_rect);
        const std::vector<float> px = pack(parts[size_t(r)], rect);
        composite_into(acc, rect, px.data(), false);
    }
    out.image = Image(spec.width, spec.height);
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const float* c = acc.at(x, y);
            const uint32_t w = pixel_word(spec.background, kernel::Accum{c[0], c[1], c[2], c[3]});
            std::memcpy(out.image.pixel(x, y), &w, 4);
        }
    return out;
}

// Within 1 of 255 everywhere, identical on >= 99% of the pixels.
void expect_close(const Image& a, const Image& b, const std::string& what) {
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    size_t differ = 0, worst = 0;
    for (size_t p = 0; p < a.rgba.size() / 4; ++p) {
        bool d = false;
        for (int c = 0; c < 4; ++c) {
            const int e = std::abs(int(a.rgba[p * 4 + c]) - int(b.rgba[p * 4 + c]));
            worst = std::max(worst, size_t(e));
            d = d || e != 0;
        }
        differ += d;
    }
    EXPECT_LE(worst, 1u) << what;
    EXPECT_LE(double(differ), 0.01 * double(a.rgba.size() / 4))
        << what << ": " << differ << " pixels differ";
}

struct Case {
    const char* name;
    Structure structure;
};

TEST(DistributedFrame, BricksTakeEverySampleOnceAndMatchOneProcess) {
    SyntheticOptions o;
    o.dims = {37, 30, 41};
    o.threads = 1;
    const Volume whole = generate(SyntheticKind::SphereShells, o);
    const TransferFunction tf = test_tf();
    // Every ray-marcher structure of the registry (accel_names()).
    const Case cases[] = {
        {"none", structure::None{}},          {"grid", structure::Grid{}},
        {"bitfield", structure::Bitfield{}},  {"kdtree", structure::KdTree{}},
        {"minmax", structure::MinMax{}},      {"minmax-interval", structure::MinMaxInterval{}},
        {"boolean", structure::Boolean{}},    {"distance", structure::Distance{}},
        {"chebyshev", structure::Chebyshev{}}};
    EXPECT_EQ(std::size(cases), accel_names().size()) << "a structure is missing here";
    Session single(Volume(whole), 1);
    single.set_transfer_function(tf);
    int view = 0;
    for (const Case& c : cases) {
        for (int n : {1, 2, 3, 4, 7}) {
            FrameSpec spec;
            spec.structure = c.structure;
            spec.width = spec.height = 48;
            spec.sampling.early_termination = std::nullopt;
            spec.camera.orbit.azimuth_deg = 37.f * float(view);
            spec.camera.orbit.elevation_deg = -50.f + 23.f * float(view % 5);
            spec.camera.orbit.projection =
                view % 3 == 2 ? Projection::Orthographic : Projection::Perspective;
            if (view % 4 == 3) {  // the eye inside the volume
                spec.camera.orbit.has_target = true;
                spec.camera.orbit.target = {15.f, 12.f, 22.f};
                spec.camera.orbit.distance = 4.f;
                spec.camera.orbit.fov_y_deg = 70.f;
            }
            ++view;
            spec.count_samples = true;
            const FrameResult ref = single.render(spec);
            const Bricked b =
                render_bricked(whole, tf, spec, n, n % 2 ? Balance::Voxels : Balance::Visible);
            const std::string what = std::string(c.name) + " ranks " + std::to_string(n);
            expect_close(b.image, ref.image, what);
            if (std::holds_alternative<structure::None>(c.structure)) {
                EXPECT_EQ(b.counts, ref.sample_counts) << what << ": every lattice sample once";
            }
            if (n == 1) {
                EXPECT_EQ(b.image.rgba, ref.image.rgba) << what << ": one brick is the frame";
            }
        }
    }
}

// Features that act on each sample alone (shading with either gradient source and every light,
// gradient opacity, clip planes, a crop box, jitter, nearest samples) through bricks on every
// kernel path this machine runs: the bricks' gradients at every voxel they interpolate are the
// whole volume's (the ghost layer, dist/decomposition.h), so each sample is the one-process
// sample and only compositing's association differs.
TEST(DistributedFrame, PerSampleFeaturesThroughBricksMatchOneProcess) {
    SyntheticOptions o;
    o.dims = {33, 28, 37};
    o.threads = 1;
    const Volume whole = generate(SyntheticKind::SphereShells, o);
    const TransferFunction tf = test_tf();
    struct Feature {
        const char* name;
        void (*set)(FrameSpec&);
    };
    const Feature features[] = {
        {"phong", [](FrameSpec& f) { f.features.shading = ShadingModel::Phong; }},
        {"phong precomputed",
         [](FrameSpec& f) {
             f.features.shading = ShadingModel::Phong;
             f.features.gradient = GradientSource::Precomputed;
         }},
        {"pbr spot",
         [](FrameSpec& f) {
             f.features.shading = ShadingModel::Pbr;
             f.features.light.kind = LightKind::Spot;
             f.features.light.position = {-20.f, 60.f, 50.f};
             f.features.light.target = {16.f, 14.f, 18.f};
             f.features.light.cone_deg = 40.f;
         }},
        {"gradient opacity",
         [](FrameSpec& f) {
             f.features.shading = ShadingModel::Phong;
             f.features.gradient_opacity.enabled = true;
             f.features.gradient_opacity.lo = 2.f;
             f.features.gradient_opacity.hi = 30.f;
         }},
        {"clip and crop",
         [](FrameSpec& f) {
             f.features.clip_planes.push_back(ClipPlane{{0.6f, -0.8f, 0.f}, -4.f});
             f.features.crop = true;
             f.features.crop_box = {{2.f, 3.f, 4.f}, {29.f, 22.f, 31.f}};
         }},
        {"jitter shaded",
         [](FrameSpec& f) {
             f.features.jitter = true;
             f.features.jitter_seed = 7;
             f.features.shading = ShadingModel::Phong;
         }},
        {"nearest shaded",
         [](FrameSpec& f) {
             f.sampling.interpolation = Interpolation::Nearest;
             f.features.shading = ShadingModel::Phong;
         }},
    };
    const test::KernelPaths kp;
    int view = 0;
    for (const Feature& feat : features) {
        for (simd::Isa isa : kp.paths) {
            simd::set_isa(isa);
            FrameSpec spec;
            feat.set(spec);
            const bool nearest = spec.sampling.interpolation == Interpolation::Nearest;
            spec.structure = view % 3 == 0   ? Structure{structure::None{}}
                             : view % 3 == 1 ? Structure{structure::Grid{}}
                                             : Structure{structure::Bitfield{}};
            if (nearest) spec.structure = structure::None{};
            spec.width = spec.height = 40;
            spec.sampling.early_termination = std::nullopt;
            spec.camera.orbit.azimuth_deg = 41.f * float(view);
            spec.camera.orbit.elevation_deg = -40.f + 19.f * float(view % 5);
            ++view;
            Session single(Volume(whole), 1);
            single.set_transfer_function(tf);
            spec.count_samples = true;
            const FrameResult ref = single.render(spec);
            size_t lit = 0;
            for (size_t p = 0; p < ref.image.rgba.size(); p += 4)
                lit += ref.image.rgba[p] + ref.image.rgba[p + 1] + ref.image.rgba[p + 2] > 0;
            EXPECT_GT(lit, ref.image.rgba.size() / 4 / 10) << feat.name << ": a frame to compare";
            for (int n : {2, 3, 7}) {
                const Bricked b =
                    render_bricked(whole, tf, spec, n, n % 2 ? Balance::Voxels : Balance::Visible);
                const std::string what = std::string(feat.name) + " " + simd::to_string(isa) +
                                         " ranks " + std::to_string(n);
                expect_close(b.image, ref.image, what);
                if (std::holds_alternative<structure::None>(spec.structure) &&
                    spec.features.clip_planes.empty() && !spec.features.crop) {
                    EXPECT_EQ(b.counts, ref.sample_counts) << what << ": every sample once";
                }
            }
        }
    }
}

TEST(DistributedFrame, BrickSessionsRefuseWhatTheyCannotRender) {
    SyntheticOptions o;
    o.dims = {16, 16, 16};
    const Volume whole = generate(SyntheticKind::Sphere, o);
    const Decomposition d = decompose_voxels(whole.dims(), 2);
    const BrickOwnership own = ownership(d, 0);
    Session s(crop_brick(whole, own.offset, brick_voxels(d, 0)), 1);
    s.set_brick(own, world_bounds(whole));
    s.set_transfer_function(test_tf());
    FrameSpec f;
    f.width = f.height = 8;
    f.features.shadows.enabled = true;  // shadow rays reach into other bricks
    EXPECT_THROW(s.render(f), FrameError);
    f.features.shadows.enabled = false;
    f.features.blend = BlendMode::Mip;  // composites by maximum, not front to back
    EXPECT_THROW(s.render(f), FrameError);
    f.features.blend = BlendMode::Composite;
    f.renderer = Renderer::Slicer;
    f.structure = structure::None{};
    EXPECT_THROW(s.render(f), FrameError);
}

}  // namespace
}  // namespace lacuna::dist
