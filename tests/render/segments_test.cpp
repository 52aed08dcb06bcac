// Segment visibility: the label bitfield octree against brute force, the segment renderer with
// the octree against the same renderer without it (byte for byte), mask mode with every label
// visible against the plain ray marcher, hiding a label against erasing it from the label map,
// label tables (JSON, MRIcron .lut) and their errors.
#include "lacuna/segments.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "accel/label_octree.h"
#include "common/rng.h"
#include "conformance/conformance_util.h"
#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"

namespace lacuna {
namespace {

using test::random_camera;
using test::Rng;
namespace fs = std::filesystem;

// Label blobs: a few random boxes of random labels over background 0 (runs and boundaries like
// an atlas), plus scattered single voxels (the thinnest structures).
Volume random_labels(Vec3i d, VoxelType type, int max_label, Rng& rng) {
    Volume v(d, type);
    const int boxes = rng.range(2, 8);
    for (int b = 0; b < boxes; ++b) {
        const int l = rng.range(1, max_label);
        int lo[3], hi[3];
        const int dd[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; ++a) {
            lo[a] = rng.range(0, dd[a] - 1);
            hi[a] = std::min(dd[a] - 1, lo[a] + rng.range(0, dd[a] / 2));
        }
        for (int k = lo[2]; k <= hi[2]; ++k)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int i = lo[0]; i <= hi[0]; ++i) v.set_value(i, j, k, float(l));
    }
    for (int s = 0; s < 6; ++s)
        v.set_value(rng.range(0, d.x - 1), rng.range(0, d.y - 1), rng.range(0, d.z - 1),
                    float(rng.range(1, max_label)));
    v.set_value(0, 0, 0, float(max_label));  // the largest label is present
    v.compute_range();
    return v;
}

Volume random_intensity(Vec3i d, Rng& rng) {
    SyntheticOptions so;
    so.dims = d;
    so.type = VoxelType::UInt8;
    so.seed = uint32_t(rng.next());
    return generate(SyntheticKind::NoiseBlobs, so);
}

// Wider opacity bumps than conformance_util.h's random_lut (up to 400 entries): masked
// renders need visible content under most labels.
TransferLut wide_random_lut(ValueRange vis, Rng& rng) {
    TransferLut lut;
    lut.vis = vis;
    lut.entries.assign(kDefaultLutSize, Rgba{});
    for (int b = rng.range(1, 3); b > 0; --b) {
        const int c = rng.range(0, kDefaultLutSize - 1), w = rng.range(0, 200);
        const float a = 0.05f + 0.9f * rng.uniform();
        for (int e = std::max(0, c - w); e <= std::min(kDefaultLutSize - 1, c + w); ++e)
            lut.entries[size_t(e)] = {rng.uniform(), rng.uniform(), rng.uniform(), a};
    }
    return lut;
}

LabelTable random_table(const Volume& labels, Rng& rng) {
    LabelTable t = default_label_table(labels);
    for (auto& s : t.styles) {
        s.visible = rng.coin(3);
        s.opacity = rng.coin(8) ? 0.f : 0.1f + 0.9f * rng.uniform();
    }
    return t;
}

void expect_same(const RenderResult& a, const RenderResult& b, const std::string& what) {
    ASSERT_EQ(a.image.rgba, b.image.rgba) << what;
    ASSERT_EQ(a.rgba_float.size(), b.rgba_float.size()) << what;
    ASSERT_EQ(0, std::memcmp(a.rgba_float.data(), b.rgba_float.data(),
                             a.rgba_float.size() * sizeof(float)))
        << what << ": float accumulations differ";
}

TEST(LabelOctree, NodeLabelSetsEqualBruteForceOverTheirVoxels) {
    Rng rng{7};
    for (int trial = 0; trial < 6; ++trial) {
        const Vec3i d{rng.range(3, 37), rng.range(3, 37), rng.range(3, 37)};
        const int max_label = trial % 2 ? rng.range(1, 60) : rng.range(130, 400);  // 1..7 words
        const Volume lab =
            random_labels(d, trial < 3 ? VoxelType::UInt16 : VoxelType::Int16, max_label, rng);
        SegmentOptions so;
        so.leaf_cells = 1 << rng.range(1, 4);
        const LabelOctree oct(lab, nullptr, so);
        ASSERT_EQ(oct.words(), (max_label + 64) / 64);
        const Pyramid& p = oct.pyramid();
        for (int l = 0; l < p.levels; ++l)
            for (int z = 0; z < p.n[l][2]; ++z)
                for (int y = 0; y < p.n[l][1]; ++y)
                    for (int x = 0; x < p.n[l][0]; ++x) {
                        const CellBox b = p.box(l, x, y, z);
                        std::vector<uint64_t> want(size_t(oct.words()), 0);
                        // Cells [lo, hi) have corners [lo, hi].
                        for (int k = b.lo[2]; k <= b.hi[2]; ++k)
                            for (int j = b.lo[1]; j <= b.hi[1]; ++j)
                                for (int i = b.lo[0]; i <= b.hi[0]; ++i) {
                                    const int v = int(lab.value(i, j, k));
                                    want[size_t(v) / 64] |= uint64_t(1) << (v % 64);
                                }
                        const uint64_t* got = oct.node_bits(p.index(l, x, y, z));
                        for (int w = 0; w < oct.words(); ++w)
                            ASSERT_EQ(got[w], want[size_t(w)])
                                << "trial " << trial << " level " << l << " node " << x << "," << y
                                << "," << z << " word " << w;
                    }
    }
}

TEST(Segments, OctreeSkippingIsByteIdenticalToMarchingEverySample) {
    Rng rng{2024};
    for (int trial = 0; trial < 24; ++trial) {
        const Vec3i d{rng.range(5, 33), rng.range(5, 33), rng.range(5, 33)};
        const int max_label = rng.coin(3) ? rng.range(130, 300) : rng.range(1, 116);
        const Volume lab = random_labels(d, max_label > 255 ? VoxelType::UInt16 : VoxelType::UInt8,
                                         max_label, rng);
        const Volume inten = random_intensity(d, rng);
        SegmentOptions so;
        so.mode = rng.coin() ? SegmentMode::Masked : SegmentMode::Labels;
        so.leaf_cells = 1 << rng.range(1, 3);
        so.tint = rng.coin() ? 0.f : rng.uniform();
        const Volume* in = so.mode == SegmentMode::Masked ? &inten : nullptr;
        SegmentOptions ref_opts = so;
        ref_opts.skip = false;
        SegmentRenderer ref(in, lab, ref_opts), fast(in, lab, so);
        const TransferLut lut = wide_random_lut(inten.vis_range(), rng);
        if (in) ref.set_transfer_function(lut), fast.set_transfer_function(lut);
        RenderOptions ro;
        ro.keep_float = ro.count_samples = true;
        ro.ert = rng.coin() ? 0.99f : kNoEarlyTermination;
        ro.step = 0.25f + rng.uniform();
        const Camera cam = random_camera(lab, rng, 36);
        // Several visibility edits on the same structure: no rebuild between them.
        for (int edit = 0; edit < 3; ++edit) {
            const LabelTable t = random_table(lab, rng);
            ref.set_labels(t);
            fast.set_labels(t);
            const RenderResult a = ref.render(cam, ro), b = fast.render(cam, ro);
            expect_same(a, b,
                        "trial " + std::to_string(trial) + " edit " + std::to_string(edit) +
                            " mode " + to_string(so.mode));
            ASSERT_LE(b.stats.samples, a.stats.samples);
        }
    }
}

TEST(Segments, MaskModeIsExactThroughEveryIntensityStructure) {
    Rng rng{31};
    for (int trial = 0; trial < 4; ++trial) {
        const Vec3i d{rng.range(6, 26), rng.range(6, 26), rng.range(6, 26)};
        const Volume lab = random_labels(d, VoxelType::UInt8, rng.range(1, 150), rng);
        const Volume inten = random_intensity(d, rng);
        const TransferLut lut = wide_random_lut(inten.vis_range(), rng);
        const LabelTable t = random_table(lab, rng);
        SegmentOptions so;
        so.skip = false;
        so.tint = rng.uniform();
        SegmentRenderer seg(&inten, lab, so);
        seg.set_transfer_function(lut);
        seg.set_labels(t);
        RenderOptions ro;
        ro.keep_float = ro.count_samples = true;
        ro.ert = rng.coin() ? 0.99f : kNoEarlyTermination;
        const Camera cam = random_camera(inten, rng, 30);
        for (Interpolation interp : {Interpolation::Trilinear, Interpolation::Nearest}) {
            ro.interpolation = interp;
            const RenderResult ref = seg.render(cam, ro);
            for (AccelKind k : all_accel_kinds()) {
                if (k == AccelKind::None) continue;
                AccelOptions ao;
                ao.interpolation = interp;  // nearest: bitfield and grid keep sets with holes
                auto accel = make_accel(k, inten, ao);
                accel->set_transfer_function(lut);
                seg.set_accel(accel.get());
                const RenderResult r = seg.render(cam, ro);
                seg.set_accel(nullptr);
                expect_same(r, ref,
                            "trial " + std::to_string(trial) + " accel " + to_string(k) + " " +
                                to_string(interp));
                ASSERT_LE(r.stats.samples, ref.stats.samples) << to_string(k);
            }
        }
    }
}

TEST(Segments, MaskWithEveryLabelVisibleIsTheRayMarcherToTheBit) {
    Rng rng{99};
    for (int trial = 0; trial < 6; ++trial) {
        const Vec3i d{rng.range(6, 30), rng.range(6, 30), rng.range(6, 30)};
        const Volume lab = random_labels(d, VoxelType::UInt8, 40, rng);
        const Volume inten = random_intensity(d, rng);
        const TransferLut lut = wide_random_lut(inten.vis_range(), rng);
        LabelTable t = default_label_table(lab);
        for (auto& s : t.styles) s.visible = true, s.opacity = 1.f;
        SegmentOptions so;
        so.skip = rng.coin();
        SegmentRenderer seg(&inten, lab, so);
        seg.set_transfer_function(lut);
        seg.set_labels(t);
        RayMarcher m(inten);
        m.set_transfer_function(lut);
        RenderOptions ro;
        ro.keep_float = true;
        ro.ert = rng.coin() ? 0.99f : kNoEarlyTermination;
        const Camera cam = random_camera(inten, rng, 32);
        expect_same(seg.render(cam, ro), m.render(cam, ro), "trial " + std::to_string(trial));
        ro.interpolation = Interpolation::Nearest;
        const RenderResult sn = seg.render(cam, ro), mn = m.render(cam, ro);
        expect_same(sn, mn, "trial " + std::to_string(trial) + " nearest");
    }
}

TEST(Segments, HidingALabelEqualsErasingItFromTheLabelMap) {
    Rng rng{5};
    for (int trial = 0; trial < 8; ++trial) {
        const Vec3i d{rng.range(6, 28), rng.range(6, 28), rng.range(6, 28)};
        const Volume lab = random_labels(d, VoxelType::UInt8, 12, rng);
        const int hidden = rng.range(1, 12);
        Volume erased(d, VoxelType::UInt8);
        std::memcpy(erased.data(), lab.data(), lab.bytes());
        for (size_t i = 0; i < erased.voxel_count(); ++i)
            if (erased.data_as<uint8_t>()[i] == hidden) erased.data_as<uint8_t>()[i] = 0;
        erased.data_as<uint8_t>()[0] = 12;  // keep the label count
        LabelTable t = default_label_table(lab);
        for (auto& s : t.styles) s.opacity = 0.3f + 0.7f * rng.uniform();
        LabelTable t_hidden = t;
        t_hidden.styles[size_t(hidden)].visible = false;
        if (lab.data_as<uint8_t>()[0] == hidden) continue;  // voxel 0 was restored above
        SegmentOptions so;
        so.mode = SegmentMode::Labels;
        so.skip = rng.coin();
        SegmentRenderer a(nullptr, lab, so), b(nullptr, erased, so);
        a.set_labels(t_hidden);
        b.set_labels(t);  // label 0 is hidden by default
        RenderOptions ro;
        ro.keep_float = true;
        const Camera cam = random_camera(lab, rng, 32);
        expect_same(a.render(cam, ro), b.render(cam, ro), "trial " + std::to_string(trial));
    }
}

TEST(Segments, EveryLabelHiddenGivesTheBackgroundAndTheOctreeSkipsTheWholeRay) {
    Rng rng{11};
    const Volume lab = random_labels({20, 17, 23}, VoxelType::UInt8, 30, rng);
    LabelTable t = default_label_table(lab);
    set_label_visibility(t, "none", true, "test");
    SegmentOptions so;
    so.mode = SegmentMode::Labels;
    SegmentRenderer seg(nullptr, lab, so);
    seg.set_labels(t);
    RenderOptions ro;
    ro.background = {0.25f, 0.5f, 0.75f};
    const Camera cam = random_camera(lab, rng, 24);
    const RenderResult r = seg.render(cam, ro);
    // The root is empty: only the cursor's safety margins at the box faces are marched (the
    // lattice rounding takes at most two samples at each end of a cut).
    EXPECT_GT(r.stats.rays, 0u);
    EXPECT_LE(r.stats.samples, 4 * r.stats.rays);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            const uint8_t* p = r.image.pixel(x, y);
            ASSERT_EQ(p[0], 64);
            ASSERT_EQ(p[1], 128);
            ASSERT_EQ(p[2], 191);
        }
}

TEST(Segments, SingleLabelSlabMatchesTheAnalyticTransmittance) {
    // Label 1 fills the whole grid; an orthographic ray along z through it takes n samples of
    // step-corrected opacity a' = 1 - (1 - a)^step, so the accumulated opacity is 1 - (1-a')^n.
    Volume lab({9, 9, 41}, VoxelType::UInt8);
    for (size_t i = 0; i < lab.voxel_count(); ++i) lab.data_as<uint8_t>()[i] = 1;
    lab.compute_range();
    LabelTable t = default_label_table(lab);
    t.styles[1].opacity = 0.05f;
    SegmentOptions so;
    so.mode = SegmentMode::Labels;
    SegmentRenderer seg(nullptr, lab, so);
    seg.set_labels(t);
    OrbitParams p;
    p.projection = Projection::Orthographic;
    p.elevation_deg = 89.9f;  // looking (almost exactly) down the z axis
    const Camera cam = Camera::orbit(seg.bounds(), p, 15, 15);
    for (float step : {0.25f, 0.5f, 1.f}) {
        RenderOptions ro;
        ro.keep_float = ro.count_samples = true;
        ro.ert = kNoEarlyTermination;
        ro.step = step;
        const RenderResult r = seg.render(cam, ro);
        const size_t c = size_t(7) * 15 + 7;
        const float n = float(r.sample_counts[c]);
        EXPECT_NEAR(n, 40.f / step, 1.f);
        const double ap = 1.0 - std::pow(1.0 - 0.05, double(step));
        EXPECT_NEAR(r.rgba_float[c * 4 + 3], 1.0 - std::pow(1.0 - ap, double(n)), 1e-4);
        // and the physical transmittance exp(-sigma L) with 1 - a = exp(-sigma) per voxel
        EXPECT_NEAR(1.0 - r.rgba_float[c * 4 + 3], std::pow(0.95, n * step), 1e-3);
    }
}

TEST(LabelTable, JsonStylesAndVisibilityLists) {
    Volume lab({4, 4, 4}, VoxelType::UInt8);
    lab.set_value(1, 1, 1, 9);
    lab.compute_range();
    const fs::path p = fs::temp_directory_path() / "lacuna-labels-test.json";
    std::ofstream(p) << R"({"name": "t", "labels": [
        {"label": 3, "name": "three", "color": [1, 0, 0.5], "opacity": 0.25},
        {"label": 12, "visible": false}]})";
    const LabelTable t = load_label_table(p.string(), lab);
    ASSERT_EQ(t.size(), 13);
    EXPECT_EQ(t.styles[3].name, "three");
    EXPECT_EQ(t.styles[3].r, 1.f);
    EXPECT_EQ(t.styles[3].b, 0.5f);
    EXPECT_EQ(t.styles[3].opacity, 0.25f);
    EXPECT_FALSE(t.styles[12].visible);
    EXPECT_FALSE(t.styles[0].visible);
    EXPECT_TRUE(t.styles[9].visible);
    LabelTable u = t;
    set_label_visibility(u, "1,4-6", false, "--hide");
    EXPECT_FALSE(u.styles[1].visible);
    EXPECT_FALSE(u.styles[5].visible);
    EXPECT_TRUE(u.styles[3].visible);
    set_label_visibility(u, "none", true, "--show");
    for (int l = 1; l < u.size(); ++l) EXPECT_FALSE(u.styles[size_t(l)].visible);
    for (const char* bad : {"1,,x", "5-2", "99999999", "-3", ""})
        EXPECT_THROW(set_label_visibility(u, bad, true, "--show"), Error) << bad;
    const std::pair<const char*, const char*> malformed[] = {
        {R"({"labels": [{"label": -1}]})", "labels[0].label"},
        {R"({"labels": [{"label": 2, "color": [1, 2, 0]}]})", "labels[0].color[1]"},
        {R"({"labels": [{"label": 2, "opacity": "x"}]})", "labels[0].opacity"},
        {R"({"labels": [{"label": 2, "colour": [1, 1, 1]}]})", "labels[0].colour"},
        {R"({"labels": 3})", "labels"},
        {R"({"labels": [)", "JSON"},
    };
    for (const auto& [text, field] : malformed) {
        std::ofstream(p) << text;
        try {
            load_label_table(p.string(), lab);
            ADD_FAILURE() << "accepted " << text;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
        }
    }
    fs::remove(p);
}

TEST(LabelTable, ReadsMricronColourTablesAndNames) {
    const fs::path dir = fs::temp_directory_path() / "lacuna-lut-test";
    fs::create_directories(dir);
    std::string bytes(768, '\0');
    bytes[5] = char(200), bytes[256 + 5] = char(100), bytes[512 + 5] = char(50);
    std::ofstream(dir / "atlas.lut", std::ios::binary) << bytes;
    std::ofstream(dir / "atlas.txt") << "5 Hippocampus_L 4101\n6 Hippocampus_R 4102\n";
    Volume lab({4, 4, 4}, VoxelType::UInt8);
    lab.set_value(0, 0, 0, 6);
    lab.compute_range();
    const LabelTable t = load_label_table((dir / "atlas.lut").string(), lab);
    EXPECT_EQ(t.styles[5].r, 200.f / 255.f);
    EXPECT_EQ(t.styles[5].g, 100.f / 255.f);
    EXPECT_EQ(t.styles[5].b, 50.f / 255.f);
    EXPECT_EQ(t.styles[5].name, "Hippocampus_L");
    EXPECT_EQ(t.styles[6].name, "Hippocampus_R");
    std::ofstream(dir / "short.lut", std::ios::binary) << "abc";
    EXPECT_THROW(load_label_table((dir / "short.lut").string(), lab), Error);
    fs::remove_all(dir);
}

TEST(Segments, RejectsFloatLabelsNegativeLabelsAndMismatchedDims) {
    Volume f({4, 4, 4}, VoxelType::Float32);
    f.compute_range();
    EXPECT_THROW(check_label_volume(f, nullptr, "x"), Error);
    Volume neg({4, 4, 4}, VoxelType::Int16);
    neg.set_value(1, 2, 3, -4);
    EXPECT_THROW(check_label_volume(neg, nullptr, "x"), Error);
    Volume a({4, 4, 4}, VoxelType::UInt8), b({4, 5, 4}, VoxelType::UInt8);
    EXPECT_THROW(check_label_volume(a, &b, "x"), Error);
    EXPECT_NO_THROW(check_label_volume(a, nullptr, "x"));
}

TEST(Segments, AalAtlasOverCh2IsExactAndSkipsHiddenRegions) {
    const std::string dir = "/usr/share/mricron/templates/";
    if (!fs::exists(dir + "aal.nii.gz") || !fs::exists(dir + "ch2.nii.gz"))
        GTEST_FAIL() << "mricron-data is not installed (scripts/install-deps installs it)";
    const Volume head = read_volume(dir + "ch2.nii.gz");
    const Volume aal = read_volume(dir + "aal.nii.gz");
    LabelTable t = default_label_table(aal);
    ASSERT_EQ(t.size(), 117);
    set_label_visibility(t, "none", true, "test");
    set_label_visibility(t, "37-42", true, "test");  // hippocampi, parahippocampal, amygdalae
    TransferLut lut = discretise(preset("mr-brain"), head.vis_range());
    SegmentOptions fast_o, ref_o;
    ref_o.skip = false;
    SegmentRenderer fast(&head, aal, fast_o), ref(&head, aal, ref_o);
    EXPECT_EQ(fast.stats().label_words, 2);  // 117 labels: 128-bit nodes
    for (SegmentRenderer* s : {&fast, &ref}) s->set_transfer_function(lut), s->set_labels(t);
    OrbitParams p;
    p.azimuth_deg = 120.f;
    const Camera cam = Camera::orbit(fast.bounds(), p, 48, 48);
    RenderOptions ro;
    ro.keep_float = true;
    const RenderResult a = ref.render(cam, ro), b = fast.render(cam, ro);
    expect_same(a, b, "aal/ch2");
    EXPECT_LT(b.stats.samples * 5, a.stats.samples) << "six small regions: most samples skipped";
    int lit = 0;
    for (size_t i = 3; i < b.rgba_float.size(); i += 4) lit += b.rgba_float[i] > 0.f;
    EXPECT_GT(lit, 10) << "the regions are visible";
}

}  // namespace
}  // namespace lacuna
