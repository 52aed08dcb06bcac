// Session: a frame through the session is the frame of the hand-wired renderers byte for byte;
// a TF change through it gives the image of a fresh session with that TF (the structures catch
// up); structures are built once and reused across frames and TF changes.
#include "lacuna/session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lacuna/accel.h"
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"
#include "lacuna/segments.h"
#include "lacuna/synthetic.h"
#include "slice/box_sources.h"
#include "slice/slice_renderer.h"

namespace lacuna {
namespace {

Volume blobs() {
    SyntheticOptions so;
    so.dims = {34, 29, 23};
    so.seed = 11;
    return generate(SyntheticKind::NoiseBlobs, so);
}

Volume label_blobs() {
    SyntheticOptions so;
    so.dims = {34, 29, 23};
    so.seed = 4;
    return generate(SyntheticKind::NoiseBlobs, so);
}

// A large uniform block of 180 in empty space: under a TF that shows only low values its
// interior is invisible (every structure skips it), under one that shows 180 it is not.
Volume block() {
    Volume v({40, 36, 32}, VoxelType::UInt8);
    for (int k = 4; k < 28; ++k)
        for (int j = 4; j < 32; ++j)
            for (int i = 4; i < 36; ++i) v.set_value(i, j, k, 180.f);
    v.set_value(0, 0, 0, 255.f);  // the range's top: 180 is 0.71 of it
    v.compute_range();
    return v;
}

// A TF visible only on [lo, hi] of the normalized range: two with disjoint windows make a
// structure that kept the first TF skip everything the second one shows.
TransferFunction window(double lo, double hi) {
    TransferFunction tf;
    tf.name = "window";
    tf.color = {{0.0, 1.f, 0.5f, 0.2f}, {1.0, 0.2f, 0.6f, 1.f}};
    tf.opacity = {{0.0, 0.f}, {lo, 0.f}, {0.5 * (lo + hi), 0.6f}, {hi, 0.f}, {1.0, 0.f}};
    return tf;
}

FrameSpec spec(Structure s) {
    FrameSpec f;
    f.structure = std::move(s);
    f.width = 37;
    f.height = 31;
    f.camera.orbit.azimuth_deg = 40.f;
    f.camera.orbit.elevation_deg = 25.f;
    return f;
}

RenderOptions options_of(const FrameSpec& f) {
    RenderOptions ro;
    ro.step = f.sampling.step;
    ro.ert = f.sampling.early_termination.value_or(kNoEarlyTermination);
    ro.threads = 1;
    ro.features = f.features;
    return ro;
}

TEST(Session, RayMarcherFramesAreTheHandWiredFrames) {
    const Volume vol = blobs();
    const TransferLut lut = discretise(window(0.3, 0.7), vol.vis_range());
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.3, 0.7));
    for (AccelKind k : all_accel_kinds()) {
        for (bool refine : {false, true}) {
            const FrameSpec f = spec(structure_of(k));
            auto accel = make_accel(k, vol, {});
            accel->set_transfer_function(lut);
            if (refine) accel->refine();
            RayMarcher marcher(vol);
            marcher.set_transfer_function(lut);
            marcher.set_accel(accel.get());
            const Camera cam = Camera::orbit(marcher.bounds(), f.camera.orbit, f.width, f.height);
            const RenderResult direct = marcher.render(cam, options_of(f));
            session.prepare(f);
            if (refine) session.refine();
            const FrameResult r = session.render(f);
            EXPECT_TRUE(r.image.rgba == direct.image.rgba) << to_string(k) << " refine " << refine;
            EXPECT_EQ(r.stats.samples, direct.stats.samples)
                << to_string(k) << " refine " << refine;
        }
    }
}

TEST(Session, TwoTfFramesAreTheHandWiredFrames) {
    const Volume vol = blobs();
    const TransferLut front = discretise(window(0.3, 0.6), vol.vis_range());
    const TransferLut back = discretise(window(0.5, 0.9), vol.vis_range());
    FrameSpec f = spec(structure::Grid{});
    f.features.clip_planes.push_back({{1, 0, 0}, 8.f});
    f.two_tfs = true;
    auto accel = make_accel(AccelKind::Grid, vol, {});
    accel->set_transfer_function(union_lut(front, back));
    RayMarcher marcher(vol);
    marcher.set_transfer_function(front);
    marcher.set_back_transfer_function(back);
    marcher.set_accel(accel.get());
    const Camera cam = Camera::orbit(marcher.bounds(), f.camera.orbit, f.width, f.height);
    const RenderResult direct = marcher.render(cam, options_of(f));
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.3, 0.6));
    session.set_back_transfer_function(window(0.5, 0.9));
    EXPECT_TRUE(session.render(f).image.rgba == direct.image.rgba);
    // The same structure without two_tfs holds the front TF alone again: the one-TF frame.
    f.two_tfs = false;
    Session one(blobs(), 1);
    one.set_transfer_function(window(0.3, 0.6));
    EXPECT_TRUE(session.render(f).image.rgba == one.render(f).image.rgba);
}

// The registry's box faces are the box sources the slicer's factory knows.
TEST(Session, TheSlicersStructuresAreTheBoxSources) {
    std::vector<std::string> boxes;
    for (const Structure& s : all_structures())
        if (capabilities(Renderer::Slicer).takes(s)) boxes.push_back(structure_name(s));
    EXPECT_EQ(boxes, box_source_names());
}

TEST(Session, SlicerFramesAreTheHandWiredFrames) {
    const Volume vol = blobs();
    const TransferLut lut = discretise(window(0.3, 0.7), vol.vis_range());
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.3, 0.7));
    const std::pair<Structure, std::string> sources[] = {{structure::None{}, "none"},
                                                         {structure::KdTree{}, "kdtree"},
                                                         {structure::GrowingBoxes{}, "boxes"}};
    for (const auto& [st, name] : sources) {
        FrameSpec f = spec(st);
        f.renderer = Renderer::Slicer;
        AccelOptions ao;
        ao.threads = 1;
        auto source = make_box_source(name, vol, ao);
        source->set_transfer_function(lut);
        SliceRenderer slicer(vol);
        slicer.set_transfer_function(lut);
        if (name != "none") slicer.set_box_source(source.get());
        SliceOptions o;
        o.step = f.sampling.step;
        o.ert = *f.sampling.early_termination;
        o.threads = 1;
        const Camera cam = Camera::orbit(slicer.bounds(), f.camera.orbit, f.width, f.height);
        EXPECT_TRUE(session.render(f).image.rgba == slicer.render(cam, o).image.rgba) << name;
    }
}

// The slicer's occlusion uses and the adaptive map updates through the session are the slicer
// driven by hand over an orbit: images, samples and the updates per frame. The adaptive
// controller learns over consecutive frames of one structure and slicer spec; a frame of another
// spec in between starts it afresh (what bench li's columns rely on).
TEST(Session, SlicerOcclusionFramesAreTheHandWiredFramesAcrossAnOrbit) {
    const Volume vol = blobs();
    const TransferFunction tf = window(0.3, 0.7);  // opaque blobs: boxes behind them hide
    const TransferLut lut = discretise(tf, vol.vis_range());
    Session session(blobs(), 1);
    session.set_transfer_function(tf);
    AccelOptions ao;
    ao.threads = 1;
    auto source = make_box_source("kdtree", vol, ao);
    source->set_transfer_function(lut);
    SliceRenderer slicer(vol);
    slicer.set_transfer_function(lut);
    slicer.set_box_source(source.get());
    const std::pair<OcclusionUse, OcclusionMode> uses[] = {
        {OcclusionUse::CullClip, OcclusionMode::CullClip},
        {OcclusionUse::CullOnly, OcclusionMode::CullOnly},
        {OcclusionUse::MapOnly, OcclusionMode::MapOnly}};
    for (bool adaptive : {false, true})
        for (const auto& [use, mode] : uses) {
            AdaptiveOptions aopt;
            aopt.initial = 3;
            AdaptiveUpdates controller(aopt);
            int updates_seen = 0;
            for (int view = 0; view < 4; ++view) {
                FrameSpec f = spec(structure::KdTree{});
                f.renderer = Renderer::Slicer;
                f.camera.orbit.azimuth_deg = 90.f * float(view);
                f.slicer.occlusion = true;
                f.slicer.occlusion_use = use;
                f.slicer.occlusion_updates = 3;
                f.slicer.occlusion_map = 16;
                f.slicer.adaptive_updates = adaptive;
                SliceOptions o;
                o.step = f.sampling.step;
                o.ert = *f.sampling.early_termination;
                o.threads = 1;
                o.occlusion.mode = mode;
                o.occlusion.updates = 3;
                o.occlusion.map_size = 16;
                const Camera cam =
                    Camera::orbit(slicer.bounds(), f.camera.orbit, f.width, f.height);
                const SliceResult hand = slicer.render(cam, o, adaptive ? &controller : nullptr);
                const FrameResult r = session.render(f);
                const std::string what = to_string(mode) + (adaptive ? " adaptive" : "") +
                                         " view " + std::to_string(view);
                EXPECT_TRUE(r.image.rgba == hand.image.rgba) << what;
                EXPECT_EQ(r.stats.samples, hand.stats.samples) << what;
                ASSERT_TRUE(r.slicer.has_value());
                EXPECT_EQ(r.slicer->desired_updates, hand.stats.desired_updates) << what;
                EXPECT_EQ(r.slicer->map_updates, hand.stats.map_updates) << what;
                EXPECT_DOUBLE_EQ(r.slicer->voxels, hand.stats.voxels) << what;
                updates_seen += hand.stats.map_updates;
            }
            EXPECT_GT(updates_seen, 0) << to_string(mode);  // the map was in use
        }
    // Frames of another slicer spec in between: the next adaptive frame starts from a fresh
    // controller, as a fresh session would.
    FrameSpec f = spec(structure::KdTree{});
    f.renderer = Renderer::Slicer;
    f.slicer.occlusion = true;
    f.slicer.adaptive_updates = true;
    f.slicer.occlusion_updates = 2;
    Session fresh(blobs(), 1);
    fresh.set_transfer_function(tf);
    for (int view = 0; view < 12; ++view) {
        f.camera.orbit.azimuth_deg = 30.f * float(view);
        session.render(f);
    }
    FrameSpec other = f;
    other.slicer.occlusion_use = OcclusionUse::CullOnly;
    session.render(other);
    for (int view = 0; view < 12; ++view) {
        f.camera.orbit.azimuth_deg = 30.f * float(view);
        EXPECT_EQ(session.render(f).slicer->desired_updates,
                  fresh.render(f).slicer->desired_updates)
            << view;
    }
}

TEST(Session, SegmentFramesAreTheHandWiredFrames) {
    const Volume vol = blobs(), labels = label_blobs();
    const TransferLut lut = discretise(window(0.2, 0.8), vol.vis_range());
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.2, 0.8));
    session.set_labels(label_blobs());
    LabelTable table = default_label_table(labels);
    set_label_visibility(table, "1-60", false, "hide");
    for (const Structure& st : {Structure{structure::LabelOctree{}}, Structure{structure::None{}},
                                Structure{structure::MinMax{}}}) {
        FrameSpec f = spec(st);
        f.renderer = Renderer::Segments;
        f.segments.labels = table;
        SegmentOptions so;
        so.skip = std::holds_alternative<structure::LabelOctree>(st);
        SegmentRenderer seg(&vol, labels, so);
        seg.set_transfer_function(lut);
        std::unique_ptr<Accel> accel;
        if (std::holds_alternative<structure::MinMax>(st)) {
            accel = make_accel(AccelKind::MinMax, vol, {});
            accel->set_transfer_function(lut);
            seg.set_accel(accel.get());
        }
        seg.set_labels(table);
        const Camera cam = Camera::orbit(seg.bounds(), f.camera.orbit, f.width, f.height);
        const RenderResult direct = seg.render(cam, options_of(f));
        const FrameResult r = session.render(f);
        EXPECT_TRUE(r.image.rgba == direct.image.rgba) << structure_name(st);
        EXPECT_EQ(r.stats.samples, direct.stats.samples) << structure_name(st);
    }
}

TEST(Session, ATfChangeGivesTheImageOfAFreshSessionWithThatTf) {
    Session session(block(), 1);
    session.set_transfer_function(window(0.15, 0.35));
    for (AccelKind k : all_accel_kinds()) session.render(spec(structure_of(k)));
    session.refine();
    // Every structure was built and refined for the first TF, under which the block's interior
    // is invisible; the second shows it, so a structure that missed the change would skip it.
    ASSERT_TRUE(session.set_transfer_function(window(0.55, 0.85)));
    Session fresh(block(), 1);
    fresh.set_transfer_function(window(0.55, 0.85));
    const FrameResult reference = fresh.render(spec(structure::None{}));
    for (AccelKind k : all_accel_kinds()) {
        const FrameSpec f = spec(structure_of(k));
        EXPECT_TRUE(session.render(f).image.rgba == reference.image.rgba) << to_string(k);
        EXPECT_TRUE(fresh.render(f).image.rgba == reference.image.rgba) << to_string(k);
    }
    // Setting the same TF again is no change.
    EXPECT_FALSE(session.set_transfer_function(window(0.55, 0.85)));
}

TEST(Session, StructuresAreBuiltOnceAndReused) {
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.3, 0.7));
    EXPECT_EQ(session.built_count(), 0u);
    const FrameSpec grid = spec(structure::Grid{});
    const FrameResult first = session.render(grid);
    EXPECT_GT(first.build_seconds, 0.0);
    EXPECT_EQ(session.built_count(), 1u);
    const FrameResult second = session.render(grid);
    EXPECT_EQ(second.build_seconds, 0.0);
    EXPECT_EQ(second.tf_sync_seconds, 0.0);  // it holds the TF already
    EXPECT_TRUE(second.image.rgba == first.image.rgba);
    // Another structure, or the same one with other parameters, is a second build ...
    session.render(spec(structure::Bitfield{}));
    session.render(spec(structure::Bitfield{{4, -1, true}, 64}));
    EXPECT_EQ(session.built_count(), 3u);
    // ... a TF change rebuilds nothing (it updates), and going back to the grid reuses it.
    session.set_transfer_function(window(0.2, 0.5));
    const FrameResult after = session.render(grid);
    EXPECT_EQ(after.build_seconds, 0.0);
    EXPECT_GT(after.tf_sync_seconds, 0.0);
    EXPECT_EQ(session.built_count(), 3u);
    // The slicer's box source and the segment renderer are built once too.
    session.set_labels(label_blobs());
    FrameSpec boxes = spec(structure::KdTree{});
    boxes.renderer = Renderer::Slicer;
    FrameSpec seg = spec(structure::LabelOctree{});
    seg.renderer = Renderer::Segments;
    for (int i = 0; i < 2; ++i) {
        EXPECT_EQ(session.render(boxes).build_seconds > 0.0, i == 0);
        EXPECT_EQ(session.render(seg).build_seconds > 0.0, i == 0);
    }
    EXPECT_EQ(session.built_count(), 5u);
    session.drop_structures();
    EXPECT_EQ(session.built_count(), 0u);
    EXPECT_TRUE(session.render(grid).image.rgba == after.image.rgba);
}

TEST(Session, RefusesFramesItCannotRender) {
    Session session(blobs(), 1);
    EXPECT_THROW(session.render(spec(structure::Grid{})), Error);  // no TF yet
    session.set_transfer_function(window(0.3, 0.7));
    FrameSpec f = spec(structure::Grid{});
    f.features.clip_planes.push_back({{1, 0, 0}, 8.f});
    f.two_tfs = true;
    EXPECT_THROW(session.render(f), Error);  // no back TF
    FrameSpec seg = spec(structure::LabelOctree{});
    seg.renderer = Renderer::Segments;
    EXPECT_THROW(session.render(seg), Error);  // mask mode without labels
    // Labels mode reads the volume itself as the label map, TF or not.
    Session labels(label_blobs(), 1);
    seg.segments.mode = SegmentMode::Labels;
    EXPECT_GT(labels.render(seg).stats.samples, 0u);
}

TEST(Session, PanZeroIsTheOrbitCameraAndPanMovesIt) {
    Session session(blobs(), 1);
    FrameSpec f = spec(structure::None{});
    const Camera orbit =
        Camera::orbit(world_bounds(session.volume()), f.camera.orbit, f.width, f.height);
    EXPECT_EQ(to_string(session.camera(f)), to_string(orbit));
    f.camera.pan_x = 0.25f;
    EXPECT_NE(to_string(session.camera(f)), to_string(orbit));
}

// The up vector rolls the camera: its negation turns right and up into their exact negations
// (cross products of negated vectors), so the image is the default one turned by 180 degrees up
// to the rounding of the pixel grid's coordinates; a tilted up differs from both.
TEST(Session, UpRollsTheCameraAndItsNegationTurnsTheImage) {
    Session session(blobs(), 1);
    session.set_transfer_function(window(0.3, 0.7));
    FrameSpec f = spec(structure::None{});
    const Camera c0 = session.camera(f);
    const FrameResult a = session.render(f);
    f.camera.orbit.up = {0, 0, -1};
    const Camera c1 = session.camera(f);
    EXPECT_EQ(to_string(c1.eye()), to_string(c0.eye()));
    EXPECT_EQ(to_string(c1.forward()), to_string(c0.forward()));
    for (int i = 0; i < 3; ++i) {  // == also takes 0 for -0
        EXPECT_EQ(c1.right()[i], -c0.right()[i]) << i;
        EXPECT_EQ(c1.up()[i], -c0.up()[i]) << i;
    }
    const FrameResult b = session.render(f);
    const int w = f.width, h = f.height;
    long diff = 0, nonzero = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                const int p = a.image.pixel(x, y)[c], q = b.image.pixel(w - 1 - x, h - 1 - y)[c];
                diff += std::abs(p - q);
                nonzero += p != 0;
            }
    EXPECT_GT(nonzero, 40);                       // the frame shows something
    EXPECT_LE(double(diff) / (w * h * 3), 0.05);  // the turned image, up to a lattice rounding
    f.camera.orbit.up = {1, 0, 1};
    EXPECT_FALSE(session.render(f).image.rgba == a.image.rgba);
}

// keep_float hands back each renderer's premultiplied RGBA, from which the 8-bit image is
// round(clamp(rgb + (1 - a) * background) * 255) channel by channel, over a coloured background.
TEST(Session, KeepFloatIsTheRgbaTheImageIsRoundedFrom) {
    Session session(blobs(), 1);
    session.set_labels(label_blobs());
    session.set_transfer_function(window(0.2, 0.8));
    for (const RendererCapabilities& cap : capabilities()) {
        FrameSpec f = spec(structure::None{});
        f.renderer = cap.renderer;
        f.background = {0.25f, 0.5f, 0.75f};
        const FrameResult plain = session.render(f);
        EXPECT_TRUE(plain.rgba_float.empty());
        f.keep_float = true;
        const FrameResult r = session.render(f);
        EXPECT_TRUE(r.image.rgba == plain.image.rgba) << to_string(cap.renderer);
        ASSERT_EQ(r.rgba_float.size(), size_t(f.width) * f.height * 4) << to_string(cap.renderer);
        int seen = 0;
        for (int y = 0; y < f.height; ++y)
            for (int x = 0; x < f.width; ++x) {
                const float* q = &r.rgba_float[(size_t(y) * f.width + x) * 4];
                ASSERT_GE(q[3], 0.f);
                ASSERT_LE(q[3], 1.f);
                seen += q[3] > 0.f;
                const float bg[3] = {f.background.x, f.background.y, f.background.z};
                for (int c = 0; c < 3; ++c) {
                    const float v = std::clamp(q[c] + (1.f - q[3]) * bg[c], 0.f, 1.f) * 255.f;
                    ASSERT_EQ(int(r.image.pixel(x, y)[c]), int(std::lround(v)))
                        << to_string(cap.renderer) << " at " << x << "," << y << " channel " << c;
                }
            }
        EXPECT_GT(seen, 15) << to_string(cap.renderer);
    }
}

}  // namespace
}  // namespace lacuna

namespace lacuna {
namespace {

// The conformance property through the session, for every structure of the variant on every
// renderer the capabilities table grants it: the image of the renderer without skipping, byte
// for byte, after the structure was built for another TF (a TF change) and after refine().
TEST(Session, EveryStructureGivesTheNoneImageOnEveryRendererThatTakesIt) {
    for (const bool sparse : {true, false}) {
        Session session(sparse ? block() : blobs(), 1);
        session.set_labels(sparse ? block() : label_blobs());
        session.set_transfer_function(window(0.55, 0.85));
        for (const RendererCapabilities& cap : capabilities())
            for (const Structure& st : all_structures()) {
                if (!cap.takes(st)) continue;
                FrameSpec f = spec(st);
                f.renderer = cap.renderer;
                session.render(f);  // built and synced for the first TF
            }
        session.set_transfer_function(window(0.15, 0.45));
        for (const bool refined : {false, true}) {
            if (refined) session.refine();
            for (const RendererCapabilities& cap : capabilities()) {
                FrameSpec none = spec(structure::None{});
                none.renderer = cap.renderer;
                const FrameResult reference = session.render(none);
                for (const Structure& st : all_structures()) {
                    if (!cap.takes(st)) continue;
                    FrameSpec f = none;
                    f.structure = st;
                    const FrameResult r = session.render(f);
                    EXPECT_TRUE(r.image.rgba == reference.image.rgba)
                        << to_string(cap.renderer) << " " << structure_name(st) << " sparse "
                        << sparse << " refined " << refined;
                    EXPECT_LE(r.stats.samples, reference.stats.samples) << structure_name(st);
                }
            }
        }
    }
}

}  // namespace
}  // namespace lacuna
