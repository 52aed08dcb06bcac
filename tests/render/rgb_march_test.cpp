// RGB volumes through the ray marcher (src/render/rgb_march.h): every structure gives the
// `none` image byte for byte (the structures are built on the opacity scalar), a constant colour
// renders as that colour, the opacity channel decides what is seen, and what RGB cannot render
// yet is refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "io/io_test_util.h"
#include "io/nifti_test_file.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/io.h"
#include "lacuna/rgb.h"
#include "lacuna/session.h"

namespace lacuna {
namespace {

using test::ScratchDir;

// Writes an RGB24 NIfTI file of dims with colour(i, j, k) -> {r, g, b} and reads it back.
template <class F>
Volume rgb_file(const ScratchDir& dir, Vec3i d, F colour, RgbOpacity o = RgbOpacity::Luminance) {
    std::vector<uint8_t> bytes;
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i) {
                const std::array<uint8_t, 3> c = colour(i, j, k);
                bytes.insert(bytes.end(), c.begin(), c.end());
            }
    test::NiftiSpec s;
    s.dims = d;
    s.datatype = 128;
    s.pixdim = {1.0, 1.2, 0.9};
    const std::string path = dir.file("rgb.nii.gz");
    test::write_bytes(path, test::gzip(test::nifti_bytes(s, bytes.data(), bytes.size())));
    return read_volume(path, {}, o);
}

// Three coloured balls (colour varying inside each) in a dark, faintly noisy box: under a TF
// that hides the dark most of the volume is skippable, and what shows has the data's colours.
std::array<uint8_t, 3> blobs(int i, int j, int k) {
    const int centres[3][3] = {{9, 8, 7}, {26, 19, 14}, {12, 21, 16}};
    for (int b = 0; b < 3; ++b) {
        const double r = std::hypot(i - centres[b][0], j - centres[b][1], k - centres[b][2]);
        if (r < 6.5)
            return {uint8_t(b == 0 ? 240 - 10 * i % 60 : 60 + 5 * j),
                    uint8_t(b == 1 ? 230 - 4 * k : 90 + 3 * i),
                    uint8_t(b == 2 ? 250 - 6 * j % 70 : 40 + 7 * k)};
    }
    return {uint8_t((i * 7 + j * 3) % 13), uint8_t((j * 5 + k * 11) % 11),
            uint8_t((i + k * 2) % 17)};
}

TransferFunction ramp(double lo, double hi, float top) {
    TransferFunction tf;
    tf.name = "ramp";
    tf.color = {{0.0, 0.f, 1.f, 0.f},
                {1.0, 0.f, 1.f, 0.f}};  // green: never seen (data colour wins)
    tf.opacity = {{0.0, 0.f}};
    if (lo > 0.0) tf.opacity.push_back({lo, 0.f});
    tf.opacity.push_back({hi, top});
    if (hi < 1.0) tf.opacity.push_back({1.0, top});
    return tf;
}

TransferFunction flat(float opacity) {
    TransferFunction tf = ramp(0.0, 1.0, opacity);
    tf.opacity = {{0.0, opacity}, {1.0, opacity}};
    return tf;
}

FrameSpec spec(Structure s) {
    FrameSpec f;
    f.structure = std::move(s);
    f.width = 41;
    f.height = 33;
    f.camera.orbit.azimuth_deg = 35.f;
    f.camera.orbit.elevation_deg = 20.f;
    return f;
}

std::vector<Structure> marcher_structures() {
    std::vector<Structure> out;
    for (const Structure& s : all_structures())
        if (capabilities(Renderer::RayMarcher).takes(s)) out.push_back(s);
    return out;
}

TEST(RgbMarch, EveryStructureGivesTheNoneImage) {
    ScratchDir dir;
    Session session(rgb_file(dir, {37, 29, 23}, blobs), 2);
    ASSERT_TRUE(rgb_colours(session.volume()));
    ASSERT_GE(marcher_structures().size(), 5u);
    for (const TransferFunction& tf : {ramp(0.3, 0.5, 0.4f), ramp(0.55, 0.6, 1.f)}) {
        session.set_transfer_function(tf);
        for (const Interpolation interp : {Interpolation::Trilinear, Interpolation::Nearest}) {
            for (const std::optional<float> ert :
                 {std::optional<float>(0.95f), std::optional<float>()}) {
                FrameSpec ref = spec(structure::None{});
                ref.sampling.interpolation = interp;
                ref.sampling.early_termination = ert;
                const FrameResult none = session.render(ref);
                const Image& want = none.image;
                uint64_t fewest = none.stats.samples;
                bool coloured = false;  // the data's colour, not the TF's green, is what shows
                for (int y = 0; y < want.height; ++y)
                    for (int x = 0; x < want.width; ++x)
                        coloured |= want.pixel(x, y)[0] > want.pixel(x, y)[1] + 20;
                EXPECT_TRUE(coloured);
                for (const Structure& s : marcher_structures()) {
                    FrameSpec f = spec(s);
                    f.sampling.interpolation = interp;
                    f.sampling.early_termination = ert;
                    const FrameResult r = session.render(f);
                    fewest = std::min(fewest, r.stats.samples);
                    const Image& got = r.image;
                    EXPECT_TRUE(got.rgba == want.rgba)
                        << structure_name(s) << " " << to_string(interp) << " ert "
                        << ert.value_or(-1.f);
                }
                // The structures did skip (the test compares something): on the RGB volume's
                // opacity scalar, as on any scalar volume.
                EXPECT_LT(fewest, none.stats.samples / 2) << to_string(interp);
            }
        }
    }
}

TEST(RgbMarch, ConstantColourRendersAsThatColour) {
    ScratchDir dir;
    Session session(rgb_file(dir, {9, 8, 7},
                             [](int, int, int) {
                                 return std::array<uint8_t, 3>{200, 100, 50};
                             }),
                    1);
    // Opacity 1: the first sample is opaque, so a pixel of the volume is its colour exactly.
    session.set_transfer_function(flat(1.f));
    FrameSpec f = spec(structure::None{});
    f.keep_float = true;
    const FrameResult opaque = session.render(f);
    int hit = 0;
    for (size_t p = 0; p < opaque.rgba_float.size() / 4; ++p) {
        const float* c = &opaque.rgba_float[4 * p];
        if (c[3] == 0.f) continue;
        ++hit;
        const uint8_t* px = &opaque.image.rgba[4 * p];
        EXPECT_EQ(px[0], 200);
        EXPECT_EQ(px[1], 100);
        EXPECT_EQ(px[2], 50);
    }
    EXPECT_GT(hit, 100);
    // Partial opacity: the premultiplied colour over the accumulated opacity is the colour.
    session.set_transfer_function(flat(0.05f));
    const FrameResult thin = session.render(f);
    for (size_t p = 0; p < thin.rgba_float.size() / 4; ++p) {
        const float* c = &thin.rgba_float[4 * p];
        if (c[3] == 0.f) continue;
        EXPECT_LT(c[3], 1.f);
        EXPECT_NEAR(c[0] / c[3], 200.f / 255.f, 1e-4f);
        EXPECT_NEAR(c[1] / c[3], 100.f / 255.f, 1e-4f);
        EXPECT_NEAR(c[2] / c[3], 50.f / 255.f, 1e-4f);
    }
}

// Red voxels on one side, blue on the other, black between (no cell mixes red and blue):
// opacity on r shows only red, on b only blue, on luminance both.
TEST(RgbMarch, TheOpacityChannelDecidesWhatIsSeen) {
    ScratchDir dir;
    auto halves = [](int i, int, int) {
        if (i < 5) return std::array<uint8_t, 3>{255, 0, 0};
        if (i > 7) return std::array<uint8_t, 3>{0, 0, 255};
        return std::array<uint8_t, 3>{0, 0, 0};
    };
    struct Case {
        RgbOpacity o;
        bool red, blue;
    };
    for (const Case c : {Case{RgbOpacity::R, true, false}, Case{RgbOpacity::B, false, true},
                         Case{RgbOpacity::Luminance, true, true}}) {
        Session session(rgb_file(dir, {13, 10, 9}, halves, c.o), 1);
        session.set_transfer_function(ramp(0.0, 0.01, 0.5f));
        const Image img = session.render(spec(structure::None{})).image;
        int red = 0, blue = 0;
        for (size_t p = 0; p < img.rgba.size() / 4; ++p) {
            red += img.rgba[4 * p] > 0;
            blue += img.rgba[4 * p + 2] > 0;
        }
        EXPECT_EQ(red > 0, c.red) << to_string(c.o);
        EXPECT_EQ(blue > 0, c.blue) << to_string(c.o);
    }
}

TEST(RgbMarch, WhatRgbCannotRenderIsRefusedByName) {
    ScratchDir dir;
    Session session(rgb_file(dir, {9, 8, 7}, blobs), 1);
    session.set_transfer_function(ramp(0.2, 0.4, 0.5f));
    FrameSpec shaded = spec(structure::None{});
    shaded.features.shading = ShadingModel::Phong;
    try {
        session.render(shaded);
        ADD_FAILURE() << "shading an RGB volume was accepted";
    } catch (const FrameError& e) {
        EXPECT_EQ(e.field(), "features");
    }
    FrameSpec sliced = spec(structure::None{});
    sliced.renderer = Renderer::Slicer;
    try {
        session.render(sliced);
        ADD_FAILURE() << "the slicer took an RGB volume";
    } catch (const FrameError& e) {
        EXPECT_EQ(e.field(), "renderer");
    }
}

}  // namespace
}  // namespace lacuna
