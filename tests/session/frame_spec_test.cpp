// FrameSpec: validate() names the field at fault (never a CLI flag), and the capabilities table
// agrees with what the renderers do: every structure and feature the table grants renders and
// has an effect, every one it denies is refused by validate() naming its field.
#include "lacuna/frame_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "lacuna/accel.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
#include "lacuna/synthetic.h"
#include "lacuna/transfer_function.h"

namespace lacuna {
namespace {

// The field validate() blames, or "" when it accepts the spec.
std::string blamed(const FrameSpec& s) {
    try {
        validate(s);
    } catch (const FrameError& e) {
        EXPECT_NE(std::string(e.what()).find(e.field()), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
        return e.field();
    }
    return "";
}

Volume test_volume_small() {
    SyntheticOptions so;
    so.dims = {12, 10, 9};
    so.seed = 5;
    return generate(SyntheticKind::SphereShells, so);
}

FrameSpec on(Renderer r, Structure s = structure::None{}) {
    FrameSpec f;
    f.renderer = r;
    f.structure = std::move(s);
    f.width = f.height = 24;
    return f;
}

TEST(FrameSpec, DefaultsAndEveryRenderersDefaultStructureAreValid) {
    EXPECT_EQ(blamed(FrameSpec{}), "");
    EXPECT_EQ(blamed(on(Renderer::RayMarcher, structure::Grid{})), "");
    EXPECT_EQ(blamed(on(Renderer::Slicer, structure::None{})), "");
    EXPECT_EQ(blamed(on(Renderer::Segments, structure::LabelOctree{})), "");
}

TEST(FrameSpec, EachErrorNamesItsField) {
    using Edit = std::function<void(FrameSpec&)>;
    const std::vector<std::tuple<Renderer, Edit, std::string>> cases = {
        {Renderer::RayMarcher, [](FrameSpec& f) { f.width = 0; }, "width"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.height = 20000; }, "height"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.sampling.step = 0.f; }, "sampling.step"},
        {Renderer::Slicer, [](FrameSpec& f) { f.sampling.step = 65.f; }, "sampling.step"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.sampling.early_termination = 1.f; },
         "sampling.early_termination"},
        {Renderer::Segments, [](FrameSpec& f) { f.sampling.early_termination = 0.f; },
         "sampling.early_termination"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.camera.orbit.zoom = 0.f; },
         "camera.orbit.zoom"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.camera.orbit.fov_y_deg = 180.f; },
         "camera.orbit.fov_y_deg"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.camera.orbit.azimuth_deg = NAN; },
         "camera.orbit"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.camera.pan_x = INFINITY; }, "camera.pan"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.camera.orbit.up = {0, NAN, 1};
         },
         "camera.orbit.up"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.camera.orbit.up = {0, 0, 0};
         },
         "camera.orbit.up"},
        {Renderer::RayMarcher,  // along the view: azimuth 0, elevation 0 looks along -y
         [](FrameSpec& f) {
             f.camera.orbit.azimuth_deg = f.camera.orbit.elevation_deg = 0.f;
             f.camera.orbit.up = {0, -2, 0};
         },
         "camera.orbit.up"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.background = {0, 2, 0};
         },
         "background"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.structure = structure::GrowingBoxes{}; },
         "structure"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.structure = structure::LabelOctree{}; },
         "structure"},
        {Renderer::Slicer, [](FrameSpec& f) { f.structure = structure::Bitfield{}; }, "structure"},
        {Renderer::Segments, [](FrameSpec& f) { f.structure = structure::GrowingBoxes{}; },
         "structure"},
        {Renderer::Segments,
         [](FrameSpec& f) {
             f.segments.mode = SegmentMode::Labels;
             f.structure = structure::MinMax{};
         },
         "structure"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.structure = structure::MinMax{{3, -1, true}};
         },
         "structure.octree.leaf_cells"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.structure = structure::Bitfield{{}, 7};
         },
         "structure.bits"},
        {Renderer::Segments,
         [](FrameSpec& f) {
             f.structure = structure::LabelOctree{1, 64};
         },
         "structure.leaf_cells"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.structure = structure::Distance{0}; },
         "structure.block"},
        {Renderer::Slicer, [](FrameSpec& f) { f.structure = structure::KdTree{-1}; },
         "structure.max_boxes"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.structure = structure::KdTree{0, 0, 2.f};
         },
         "structure.min_volume"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.structure = structure::KdTree{0, 0, 0.1f, 0.05f, 65};
         },
         "structure.max_depth"},
        {Renderer::Slicer, [](FrameSpec& f) { f.structure = structure::GrowingBoxes{2.f}; },
         "structure.coalesce"},
        {Renderer::Slicer,
         [](FrameSpec& f) {
             f.structure = structure::GrowingBoxes{0.25f, 0.f};
         },
         "structure.coalesce_edge"},
        {Renderer::Slicer, [](FrameSpec& f) { f.features.shading = ShadingModel::Phong; },
         "features.shading"},
        {Renderer::Segments, [](FrameSpec& f) { f.features.clip_planes.push_back({}); },
         "features.clip_planes"},
        {Renderer::Slicer, [](FrameSpec& f) { f.features.crop = true; }, "features.crop"},
        {Renderer::Segments, [](FrameSpec& f) { f.features.blend = BlendMode::Mip; },
         "features.blend"},
        {Renderer::Slicer, [](FrameSpec& f) { f.features.jitter = true; }, "features.jitter"},
        {Renderer::Slicer, [](FrameSpec& f) { f.features.gradient_opacity.enabled = true; },
         "features.gradient_opacity"},
        {Renderer::Segments, [](FrameSpec& f) { f.features.shadows.enabled = true; },
         "features.shadows"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.two_tfs = true; }, "two_tfs"},
        {Renderer::Slicer, [](FrameSpec& f) { f.count_samples = true; }, "count_samples"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.slicer.occlusion = true; }, "slicer.occlusion"},
        {Renderer::Slicer, [](FrameSpec& f) { f.slicer.occlusion_threshold = 0.f; },
         "slicer.occlusion_threshold"},
        {Renderer::Slicer, [](FrameSpec& f) { f.slicer.occlusion_map = 5000; },
         "slicer.occlusion_map"},
        {Renderer::Slicer, [](FrameSpec& f) { f.slicer.occlusion_updates = -1; },
         "slicer.occlusion_updates"},
        {Renderer::Segments, [](FrameSpec& f) { f.segments.tint = 2.f; }, "segments.tint"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.features.phong.power = -1.f; },
         "features.phong"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.features.pbr.roughness = 0.f; },
         "features.pbr"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.features.gradient_opacity.enabled = true;
             f.features.gradient_opacity.lo = 5.f;
             f.features.gradient_opacity.hi = 1.f;
         },
         "features.gradient_opacity"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.features.light.intensity = -1.f; },
         "features.light.intensity"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.features.light.kind = LightKind::Directional;
             f.features.light.direction = {0, 0, 0};
         },
         "features.light.direction"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.features.shadows.step = 0.f; },
         "features.shadows.step"},
        {Renderer::RayMarcher, [](FrameSpec& f) { f.features.shadows.light_volume_stride = 0; },
         "features.shadows.light_volume_stride"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.features.clip_planes.push_back({{0, 0, 0}, 1.f});
         },
         "features.clip_planes"},
        {Renderer::RayMarcher,
         [](FrameSpec& f) {
             f.features.crop = true;
             f.features.crop_box = {{1, 0, 0}, {0, 1, 1}};
         },
         "features.crop_box"},
    };
    for (const auto& [renderer, edit, field] : cases) {
        FrameSpec f = on(renderer);
        ASSERT_EQ(blamed(f), "") << to_string(renderer);
        edit(f);
        EXPECT_EQ(blamed(f), field) << to_string(renderer) << " expected " << field;
    }
}

TEST(FrameSpec, StructureNamesAndKindsRoundTrip) {
    std::vector<std::string> names;
    for (const Structure& s : all_structures()) {
        names.push_back(structure_name(s));
        if (const auto k = accel_kind(s)) {
            EXPECT_EQ(to_string(*k), structure_name(s));
            EXPECT_EQ(structure_of(*k), s) << structure_name(s);
            EXPECT_TRUE(accel_options(s, Interpolation::Trilinear, 0).has_value());
        } else {
            EXPECT_FALSE(accel_options(s, Interpolation::Trilinear, 0).has_value());
        }
    }
    // Every AccelKind is one alternative; boxes and the label octree are the two without one.
    for (AccelKind k : all_accel_kinds())
        EXPECT_NE(std::find(names.begin(), names.end(), to_string(k)), names.end()) << to_string(k);
    EXPECT_EQ(names.size(), all_accel_kinds().size() + 2);
    // Parameters travel: structure_of takes them from AccelOptions, accel_options gives them back.
    AccelOptions o;
    o.leaf_cells = 4;
    o.bitfield_bits = 32;
    o.initial_level = 2;
    o.bidirectional = false;
    const auto back =
        accel_options(structure_of(AccelKind::Bitfield, o), Interpolation::Nearest, 3);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->leaf_cells, 4);
    EXPECT_EQ(back->bitfield_bits, 32);
    EXPECT_EQ(back->initial_level, 2);
    EXPECT_FALSE(back->bidirectional);
    EXPECT_EQ(back->interpolation, Interpolation::Nearest);
    EXPECT_EQ(back->threads, 3);
}

// The one parser of structure names (the CLI's --accel, the viewer's accel, Python's structure=):
// every registry name gives its alternative with default parameters for a renderer that takes it,
// "auto" each renderer's default, and an unknown name is refused naming every valid one.
TEST(FrameSpec, ParseStructureIsTheRegistrysNamesForEveryRenderer) {
    for (const Structure& s : all_structures()) {
        const std::string name = structure_name(s);
        bool taken = false;
        for (const RendererCapabilities& cap : capabilities()) {
            if (!cap.takes(s)) continue;
            taken = true;
            // The segment renderer reads "bitfield" as its label octree.
            if (cap.renderer == Renderer::Segments && name == "bitfield") continue;
            EXPECT_EQ(parse_structure(name, cap.renderer), s)
                << name << " " << to_string(cap.renderer);
        }
        EXPECT_TRUE(taken) << name;
    }
    EXPECT_EQ(parse_structure("auto", Renderer::RayMarcher), structure_of(default_accel()));
    EXPECT_EQ(parse_structure("auto", Renderer::Slicer), Structure{structure::None{}});
    EXPECT_EQ(parse_structure("auto", Renderer::Segments), Structure{structure::LabelOctree{}});
    EXPECT_EQ(parse_structure("bitfield", Renderer::Segments), Structure{structure::LabelOctree{}});
    // Parameters travel into the alternative.
    AccelOptions o;
    o.leaf_cells = 16;
    o.bitfield_bits = 128;
    const Structure bitfield = structure::Bitfield{{16, -1, true}, 128};
    const Structure label_octree = structure::LabelOctree{16, 128};
    const Structure boxes = structure::GrowingBoxes{0.5f, 32.f};
    EXPECT_EQ(parse_structure("bitfield", Renderer::RayMarcher, o), bitfield);
    EXPECT_EQ(parse_structure("bitfield", Renderer::Segments, o), label_octree);
    EXPECT_EQ(parse_structure("boxes", Renderer::Slicer, o, {0.5f, 32.f}), boxes);
    for (const char* bad : {"", "octree", "Grid", "none "}) {
        try {
            parse_structure(bad, Renderer::RayMarcher);
            ADD_FAILURE() << "'" << bad << "' was accepted";
        } catch (const FrameError& e) {
            EXPECT_EQ(e.field(), "structure");
            EXPECT_NE(e.expected().find(std::string("'") + bad + "'"), std::string::npos)
                << e.what();
            for (const Structure& s : all_structures())
                EXPECT_NE(e.expected().find(structure_name(s)), std::string::npos) << e.what();
        }
    }
}

// The renderers and structures, called directly (not through validate()), blame the same fields
// and never a CLI flag.
TEST(FrameSpec, LibraryErrorsBelowValidateNameFieldsNotFlags) {
    const Volume vol = test_volume_small();
    auto field_of = [](const std::function<void()>& f) -> std::string {
        try {
            f();
        } catch (const FrameError& e) {
            EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
            return e.field();
        }
        return "";
    };
    const TransferLut lut = discretise(preset("mr-default"), vol.vis_range());
    RayMarcher m(vol);
    m.set_transfer_function(lut);
    const Camera cam = Camera::orbit(m.bounds(), OrbitParams{}, 8, 8);
    RenderOptions ro;
    ro.threads = 1;
    EXPECT_EQ(field_of([&] { m.render(cam, ro); }), "");
    RenderOptions bad = ro;
    bad.step = 0.f;
    EXPECT_EQ(field_of([&] { m.render(cam, bad); }), "sampling.step");
    bad = ro;
    bad.features.shading = ShadingModel::Phong;
    bad.features.phong.specular = -1.f;
    EXPECT_EQ(field_of([&] { m.render(cam, bad); }), "features.phong");
    AccelOptions ao;
    ao.bitfield_bits = 7;
    EXPECT_EQ(field_of([&] { make_accel(AccelKind::Bitfield, vol, ao); }), "structure.bits");
    ao = {};
    ao.leaf_cells = 3;
    EXPECT_EQ(field_of([&] { make_accel(AccelKind::MinMax, vol, ao); }),
              "structure.octree.leaf_cells");
    ao = {};
    ao.distance_block = 0;
    EXPECT_EQ(field_of([&] { make_accel(AccelKind::Chebyshev, vol, ao); }), "structure.block");
    EXPECT_EQ(field_of([] { parse_accel("octree"); }), "structure");
    EXPECT_EQ(field_of([] { parse_interpolation("cubic"); }), "sampling.interpolation");
}

// ---- The table against the renderers ------------------------------------------------------------

Volume test_volume() {
    SyntheticOptions so;
    so.dims = {20, 18, 16};
    so.seed = 3;
    return generate(SyntheticKind::SphereShells, so);
}

Volume test_labels() {
    SyntheticOptions so;
    so.dims = {20, 18, 16};
    so.seed = 7;
    return generate(SyntheticKind::NoiseBlobs, so);
}

std::unique_ptr<Session> test_session() {
    auto s = std::make_unique<Session>(test_volume(), 1);
    s->set_transfer_function(preset("mr-default"));
    TransferFunction back = preset("mr-skin");
    s->set_back_transfer_function(back);
    s->set_labels(test_labels());
    return s;
}

TEST(Capabilities, EveryStructureTheTableGrantsRendersAndEveryOtherIsRefused) {
    auto session = test_session();
    for (const RendererCapabilities& cap : capabilities()) {
        for (const Structure& st : all_structures()) {
            FrameSpec f = on(cap.renderer, st);
            if (cap.takes(st)) {
                const FrameResult r = session->render(f);
                EXPECT_EQ(r.image.width, 24)
                    << to_string(cap.renderer) << " " << structure_name(st);
            } else {
                EXPECT_EQ(blamed(f), "structure")
                    << to_string(cap.renderer) << " " << structure_name(st);
                EXPECT_THROW(session->render(f), FrameError);
            }
        }
    }
}

// A spec that uses `f` (and its baseline without it) on renderer `r`.
std::pair<FrameSpec, FrameSpec> with_feature(Renderer r, Feature feat) {
    FrameSpec base = on(r, r == Renderer::Segments ? Structure{structure::LabelOctree{}}
                                                   : Structure{structure::None{}});
    base.sampling.early_termination = std::nullopt;
    FrameSpec f = base;
    switch (feat) {
        case Feature::Shading:
            f.features.shading = ShadingModel::Phong;
            break;
        case Feature::GradientOpacity:
            f.features.gradient_opacity = {true, 5.f, 50.f};
            break;
        case Feature::Shadows:
            base.features.shading = f.features.shading = ShadingModel::Phong;
            base.features.light.kind = f.features.light.kind = LightKind::Directional;
            base.features.light.direction = f.features.light.direction = {1, 0, 0};
            f.features.shadows.enabled = true;
            break;
        case Feature::ClipPlanes:
            f.features.clip_planes.push_back({{1, 0, 0}, 10.f});
            break;
        case Feature::Crop:
            f.features.crop = true;
            f.features.crop_box = {{0, 0, 0}, {8, 17, 15}};
            break;
        case Feature::Blend:
            f.features.blend = BlendMode::Mip;
            break;
        case Feature::Jitter:
            f.features.jitter = true;
            break;
        case Feature::TwoTfs:
            base.features.clip_planes = f.features.clip_planes = {{{1, 0, 0}, 10.f}};
            f.two_tfs = true;
            break;
        case Feature::Nearest:
            f.sampling.interpolation = Interpolation::Nearest;
            break;
        case Feature::EarlyTermination:
            f.sampling.early_termination = 0.5f;
            break;
        case Feature::SampleCounts:
            f.count_samples = true;
            break;
        case Feature::Occlusion:
            f.slicer.occlusion = true;
            break;
    }
    return {base, f};
}

TEST(Capabilities, EveryFeatureTheTableGrantsHasAnEffectAndEveryOtherIsRefused) {
    auto session = test_session();
    for (const RendererCapabilities& cap : capabilities()) {
        for (Feature feat : all_features()) {
            const auto [base, f] = with_feature(cap.renderer, feat);
            const std::string what = to_string(cap.renderer) + " " + to_string(feat);
            if (!cap.has(feat)) {
                EXPECT_NE(blamed(f), "") << what;
                EXPECT_THROW(session->render(f), FrameError) << what;
                continue;
            }
            const FrameResult a = session->render(base), b = session->render(f);
            const bool effect = a.image.rgba != b.image.rgba ||
                                a.stats.samples != b.stats.samples ||
                                a.sample_counts.size() != b.sample_counts.size() ||
                                (b.slicer && b.slicer->desired_updates > 0);
            EXPECT_TRUE(effect) << what << ": the table grants it, the renderer ignores it";
        }
    }
}

}  // namespace
}  // namespace lacuna

namespace lacuna {
namespace {

// A TF's rendering fills exactly the features the user left alone, and only where the renderer
// takes them; each override keeps the user's value.
TEST(TfRendering, SetsUnsetFeaturesAndLeavesTheUsersAlone) {
    TfRendering r;
    r.shading = TfShading{0.1f, 0.9f, 0.2f, 10.f};
    r.gradient_opacity = {{0, 0.f}, {40, 1.f}};
    r.blend = BlendMode::Mip;
    const PhongParams preset_terms{0.1f, 0.9f, 0.2f, 10.f};
    auto applied = [&](const TfRenderingOverrides& given, FrameSpec f = {}) {
        apply_tf_rendering(r, f, given);
        return f;
    };
    auto same_phong = [](const PhongParams& a, const PhongParams& b) {
        return a.ambient == b.ambient && a.diffuse == b.diffuse && a.specular == b.specular &&
               a.power == b.power;
    };
    // Nothing given: all of it.
    FrameSpec f = applied({});
    EXPECT_EQ(f.features.shading, ShadingModel::Phong);
    EXPECT_TRUE(same_phong(f.features.phong, preset_terms));
    EXPECT_TRUE(f.features.gradient_opacity.enabled);
    EXPECT_EQ(f.features.gradient_opacity.points,
              (std::vector<GradientOpacityPoint>{{0.f, 0.f}, {40.f, 1.f}}));
    EXPECT_EQ(f.features.blend, BlendMode::Mip);
    EXPECT_EQ(blamed(f), "");
    // Each override alone keeps the user's value of that feature only.
    FrameSpec user;
    user.features.shading = ShadingModel::Pbr;
    user.features.phong = {0.3f, 0.5f, 0.7f, 3.f};
    user.features.gradient_opacity = {};  // "--gradient-opacity none"
    user.features.blend = BlendMode::Composite;
    f = applied({.shading = true}, user);
    EXPECT_EQ(f.features.shading, ShadingModel::Pbr);
    EXPECT_TRUE(same_phong(f.features.phong, preset_terms));  // the terms still default to r's
    EXPECT_TRUE(f.features.gradient_opacity.enabled);
    f = applied({.phong = true}, user);
    EXPECT_EQ(f.features.shading, ShadingModel::Phong);
    EXPECT_TRUE(same_phong(f.features.phong, user.features.phong));
    f = applied({.gradient_opacity = true}, user);
    EXPECT_FALSE(f.features.gradient_opacity.enabled);
    EXPECT_EQ(f.features.blend, BlendMode::Mip);
    f = applied({.blend = true}, user);
    EXPECT_EQ(f.features.blend, BlendMode::Composite);
    EXPECT_TRUE(f.features.gradient_opacity.enabled);
    f = applied({true, true, true, true}, user);
    EXPECT_EQ(f.features.shading, user.features.shading);
    EXPECT_TRUE(same_phong(f.features.phong, user.features.phong));
    EXPECT_FALSE(f.features.gradient_opacity.enabled);
    EXPECT_EQ(f.features.blend, BlendMode::Composite);
}

TEST(TfRendering, OnlyWhereTheRendererTakesItAndNeverAnIdentityFactor) {
    TfRendering r;
    r.shading = TfShading{};
    r.gradient_opacity = {{0, 0.f}, {40, 1.f}};
    r.blend = BlendMode::Mip;
    for (Renderer renderer : {Renderer::Slicer, Renderer::Segments}) {
        FrameSpec f;
        f.renderer = renderer;
        f.structure = parse_structure("auto", renderer);
        apply_tf_rendering(r, f);
        EXPECT_EQ(f.features.shading, ShadingModel::None) << to_string(renderer);
        EXPECT_FALSE(f.features.gradient_opacity.enabled) << to_string(renderer);
        EXPECT_EQ(f.features.blend, BlendMode::Composite) << to_string(renderer);
        EXPECT_EQ(blamed(f), "") << to_string(renderer);
    }
    // Slicer's usual "0 1 255 1" (1 everywhere) multiplies by 1: the feature stays off.
    TfRendering ones;
    ones.gradient_opacity = {{0, 1.f}, {255, 1.f}};
    FrameSpec f;
    apply_tf_rendering(ones, f);
    EXPECT_FALSE(f.features.gradient_opacity.enabled);
    EXPECT_EQ(f.features.shading, ShadingModel::None);
    // An empty rendering changes nothing.
    FrameSpec g;
    apply_tf_rendering(TfRendering{}, g);
    EXPECT_FALSE(g.features.any());
}

}  // namespace
}  // namespace lacuna
