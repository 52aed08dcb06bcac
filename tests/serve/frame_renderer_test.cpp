// The viewer's frames are the CLI's images: same settings, same bytes; every structure gives
// the `none` image through TF changes and structure switches; the overlay's numbers are exact.
#include "serve/frame_renderer.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../render/orientation_test_util.h"
#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/synthetic.h"
#include "serve/jpeg.h"
#include "serve/protocol.h"

namespace fs = std::filesystem;
using namespace lacuna;
using namespace lacuna::serve;

namespace {

fs::path temp_dir() {
    static fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("lacuna-serve-" + std::to_string(::getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

const fs::path& shells_file() {
    static fs::path p = [] {
        SyntheticOptions so;
        so.dims = {33, 30, 27};
        const fs::path v = temp_dir() / "shells.nrrd";
        write_volume(v.string(), generate(SyntheticKind::SphereShells, so));
        return v;
    }();
    return p;
}

ViewRequest request(AccelKind accel, const std::string& tf) {
    ViewRequest r;
    r.width = 40;
    r.height = 36;
    r.camera.azimuth = 40;
    r.camera.elevation = 20;
    r.camera.zoom = 1.3f;
    r.accel = accel;
    r.ert = false;
    r.step = 0.5f;
    r.tf = preset(tf);
    return r;
}

}  // namespace

TEST(FrameRenderer, SameBytesAsTheCliRenderer) {
    for (const bool ert : {false, true}) {
        const fs::path out = temp_dir() / (ert ? "cli_ert.png" : "cli.png");
        const std::string cmd = std::string(LACUNA_CLI_PATH) + " render " + shells_file().string() +
                                " --tf mr-default --accel bitfield --width 40 --height 36"
                                " --azimuth 40 --elevation 20 --zoom 1.3 --step 0.5 --ert " +
                                (ert ? "0.99" : "1") + " --out " + out.string() + " >/dev/null";
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
        const Image cli = read_png(out.string());

        FrameRenderer fr(read_volume(shells_file().string()));
        ViewRequest req = request(AccelKind::Bitfield, "mr-default");
        req.ert = ert;
        const Frame f = fr.render(req, 40, 36);
        ASSERT_EQ(f.image.width, cli.width);
        ASSERT_EQ(f.image.height, cli.height);
        EXPECT_EQ(f.image.rgba, cli.rgba) << "ert " << ert;
    }
}

TEST(FrameRenderer, SliceRendererFramesAreTheCliSlicer) {
    for (const char* accel : {"none", "kdtree"}) {
        const fs::path out = temp_dir() / (std::string("cli_slice_") + accel + ".png");
        const std::string cmd = std::string(LACUNA_CLI_PATH) + " render " + shells_file().string() +
                                " --tf mr-default --renderer slice --accel " + accel +
                                " --width 40 --height 36 --azimuth 40 --elevation 20 --zoom 1.3"
                                " --step 0.5 --ert 1 --out " +
                                out.string() + " >/dev/null";
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
        const Image cli = read_png(out.string());
        FrameRenderer fr(read_volume(shells_file().string()));
        ViewRequest req = request(parse_accel(accel), "mr-default");
        req.renderer = RendererKind::Slice;
        const Frame f = fr.render(req, 40, 36);
        EXPECT_EQ(f.image.rgba, cli.rgba) << accel;
        EXPECT_GT(f.stats.samples, 0u);
        // and back to the marcher on the same renderer
        req.renderer = RendererKind::March;
        EXPECT_GT(fr.render(req, 40, 36).stats.samples, 0u);
    }
}

TEST(FrameRenderer, SegmentFramesAreTheCliSegments) {
    SyntheticOptions so;
    so.dims = {33, 30, 27};
    so.seed = 5;
    const fs::path labels = temp_dir() / "labels.nrrd";
    write_volume(labels.string(), generate(SyntheticKind::NoiseBlobs, so));
    FrameRenderer fr(read_volume(shells_file().string()));
    fr.set_labels(read_volume(labels.string()));
    EXPECT_GT(fr.label_count(), 1);
    for (const char* accel : {"bitfield", "minmax", "none"}) {
        const fs::path out = temp_dir() / (std::string("cli_seg_") + accel + ".png");
        const std::string cmd = std::string(LACUNA_CLI_PATH) + " render " + shells_file().string() +
                                " --labels " + labels.string() +
                                " --hide 1-100 --tf mr-default --accel " + accel +
                                " --width 40 --height 36 --azimuth 40 --elevation 20 --zoom 1.3"
                                " --step 0.5 --ert 1 --out " +
                                out.string() + " >/dev/null";
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
        ViewRequest req = request(parse_accel(accel), "mr-default");
        req.segments = true;
        req.hide = "1-100";
        EXPECT_EQ(fr.render(req, 40, 36).image.rgba, read_png(out.string()).rgba) << accel;
    }
    Volume wrong({4, 4, 4}, VoxelType::UInt8);
    EXPECT_THROW(fr.set_labels(std::move(wrong)), Error);
}

TEST(FrameRenderer, ShadingAndClipTogglesAreTheCliFlags) {
    // The page's toggles: Phong with the headlight, and the plane keeping x <= the centre (16 mm
    // for the 33-voxel-wide shells at 1 mm).
    const fs::path out = temp_dir() / "cli_shaded.png";
    const std::string cmd = std::string(LACUNA_CLI_PATH) + " render " + shells_file().string() +
                            " --tf mr-default --accel minmax --width 40 --height 36"
                            " --azimuth 40 --elevation 20 --zoom 1.3 --step 0.5 --ert 1"
                            " --shading phong --clip -1,0,0,-16 --out " +
                            out.string() + " >/dev/null";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
    const Image cli = read_png(out.string());
    FrameRenderer fr(read_volume(shells_file().string()));
    ViewRequest req = request(AccelKind::MinMax, "mr-default");
    req.shading = true;
    req.clip = true;
    const Frame f = fr.render(req, 40, 36);
    EXPECT_EQ(f.image.rgba, cli.rgba);
    req.shading = req.clip = false;
    EXPECT_NE(fr.render(req, 40, 36).image.rgba, cli.rgba) << "the toggles change the picture";
}

// World is patient RAS (docs/formats.md): on a volume stored LPS with an origin, the page's clip
// plane is the CLI's --clip in RAS millimetres through the centre of the RAS bounding box, and a
// named view (azimuth 90: from the patient's left) is the CLI's --view left.
TEST(FrameRenderer, ClipPlaneAndViewsAreInPatientRasOnAnLpsVolume) {
    SyntheticOptions so;
    so.dims = {33, 30, 27};
    Volume v = generate(SyntheticKind::SphereShells, so);
    const double lps_identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // RAS x = -(i + 10), y = -(j + 20)
    for (int i = 0; i < 9; ++i) v.direction[i] = lps_identity[i];
    v.origin = {10, 20, -5};
    const fs::path file = temp_dir() / "shells-lps.nrrd";
    write_volume(file.string(), v);
    // RAS bounds: x -42 .. -10, so the plane keeps x <= -26: --clip -1,0,0,26.
    const fs::path out = temp_dir() / "cli_lps_clip.png";
    const std::string cmd = std::string(LACUNA_CLI_PATH) + " render " + file.string() +
                            " --tf mr-default --accel grid --width 40 --height 36"
                            " --view left --zoom 1.3 --step 0.5 --ert 1"
                            " --shading phong --clip -1,0,0,26 --out " +
                            out.string() + " >/dev/null";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
    FrameRenderer fr(read_volume(file.string()));
    ViewRequest req = request(AccelKind::Grid, "mr-default");
    req.camera.azimuth = 90;
    req.camera.elevation = 0;
    req.shading = true;
    req.clip = true;
    EXPECT_EQ(fr.render(req, 40, 36).image.rgba, read_png(out.string()).rgba);
}

// Orientation round-trips through the viewer (issue 14, item 6). The page's request, parsed by the
// protocol, with a named view and a world clip plane, is the frame `lacuna render --view V --clip
// ...` writes, byte for byte, on the asymmetric phantom stored LPS; and a plane, in patient RAS
// mm, cuts the same side of the anatomy whatever the storage: seen with a TF that shows only the
// marker on the patient's right (at x = +11), x <= 0 removes it and x >= 0 keeps it, on the RAS
// file and on its LPS copy alike, and both give the picture of the same voxels without geometry
// (world = index x spacing, no map) clipped by the same plane moved by the origin.
TEST(FrameRenderer, NamedViewsAndWorldClipPlanesRoundTripThroughTheProtocol) {
    namespace to = lacuna::test::orientation;
    const Volume ras = to::phantom();
    const fs::path ras_file = temp_dir() / "phantom-ras.nrrd",
                   lps_file = temp_dir() / "phantom-lps.nrrd",
                   tf_file = temp_dir() / "phantom.json";
    write_volume(ras_file.string(), ras);
    write_volume(lps_file.string(), to::reorder(ras, {0, 1, 2}, {true, true, false}));
    std::ofstream(tf_file) << to_json(to::phantom_tf());
    TransferFunction right_marker;  // opaque only at the right marker's values (220)
    right_marker.name = "right-marker";
    right_marker.domain = TfDomain::Value;
    right_marker.color = {{0, 1, 0.2, 0.2}, {255, 1, 0.2, 0.2}};
    right_marker.opacity = {{0, 0}, {180, 0}, {200, 0.9}, {255, 0.9}};
    auto page_request = [](const char* view, const TransferFunction& tf, nlohmann::json planes) {
        nlohmann::json j = {{"type", "render"}, {"id", 1},
                            {"width", 48},      {"height", 40},
                            {"preview", false}, {"renderer", "march"},
                            {"accel", "grid"},  {"ert", false},
                            {"step", 0.5},      {"tf", nlohmann::json::parse(to_json(tf))}};
        j["camera"] = {{"view", view}, {"zoom", 1.5}, {"pan", {0, 0}}};
        if (!planes.is_null()) j["clip_planes"] = planes;
        return parse_request(j.dump());
    };
    const nlohmann::json keep_left = {{-1, 0, 0, 0}}, keep_right = {{1, 0, 0, 0}};
    FrameRenderer lps(read_volume(lps_file.string())), rasr(read_volume(ras_file.string()));
    for (const char* view : {"left", "superior", "anterior"}) {
        const fs::path out = temp_dir() / (std::string("cli_view_") + view + ".png");
        const std::string cmd =
            std::string(LACUNA_CLI_PATH) + " render " + lps_file.string() + " --tf " +
            tf_file.string() + " --accel grid --width 48 --height 40 --view " + view +
            " --zoom 1.5 --step 0.5 --ert 1 --clip -1,0,0,0 --out " + out.string() + " >/dev/null";
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
        EXPECT_EQ(lps.render(page_request(view, to::phantom_tf(), keep_left), 48, 40).image.rgba,
                  read_png(out.string()).rgba)
            << view;
    }
    auto opaque = [](const Image& im) {  // the marker's red over the black background
        int n = 0;
        for (size_t p = 0; p < im.rgba.size(); p += 4) n += im.rgba[p] > 100;
        return n;
    };
    for (FrameRenderer* fr : {&rasr, &lps}) {
        const char* what = fr == &rasr ? "RAS" : "LPS";
        EXPECT_GT(opaque(fr->render(page_request("anterior", right_marker, {}), 96, 80).image), 10)
            << what << ": the right marker shows unclipped";
        EXPECT_EQ(
            opaque(fr->render(page_request("anterior", right_marker, keep_left), 96, 80).image), 0)
            << what << ": x <= 0 removes the patient's right";
        EXPECT_GT(
            opaque(fr->render(page_request("anterior", right_marker, keep_right), 96, 80).image),
            10)
            << what << ": x >= 0 keeps it";
    }
    // The reference: the same voxels without geometry, whose volume frame is the world itself
    // (nothing to map, so nothing to get wrong), shifted by the phantom's origin: RAS x there is
    // x + 20, so the plane x <= 0 is -x >= -20.
    Volume plain = ras;
    plain.origin = Volume(ras.dims(), ras.type()).origin;
    for (int i = 0; i < 9; ++i) plain.direction[i] = Volume(ras.dims(), ras.type()).direction[i];
    FrameRenderer ref(std::move(plain));
    const Image want =
        ref.render(page_request("anterior", to::phantom_tf(), {{-1, 0, 0, -20}}), 48, 40).image;
    to::expect_same_picture(
        rasr.render(page_request("anterior", to::phantom_tf(), keep_left), 48, 40).image, want,
        "clipped RAS file vs the plain voxels", false);
    to::expect_same_picture(
        lps.render(page_request("anterior", to::phantom_tf(), keep_left), 48, 40).image, want,
        "clipped LPS copy vs the plain voxels", false);
}

TEST(FrameRenderer, EveryStructureMatchesNoneThroughTfChangesAndSwitches) {
    SyntheticOptions so;
    so.dims = {25, 21, 19};
    FrameRenderer fr(generate(SyntheticKind::NoiseBlobs, so));
    FrameRenderer reference(generate(SyntheticKind::NoiseBlobs, so));
    // Structures are visited in turn while the TF changes between them, so each one has to
    // catch up with TF changes it missed.
    const char* tfs[] = {"mr-default", "mr-gap", "mr-brain", "mr-skin"};
    int i = 0;
    for (const AccelKind k : all_accel_kinds()) {
        for (int pass = 0; pass < 2; ++pass, ++i) {
            ViewRequest req = request(k, tfs[i % 4]);
            req.ert = pass == 1;
            req.camera.pan_x = 0.1f * float(pass);
            const Frame f = fr.render(req, 32, 24);
            req.accel = AccelKind::None;
            const Frame ref = reference.render(req, 32, 24);
            EXPECT_EQ(f.image.rgba, ref.image.rgba) << to_string(k) << " pass " << pass;
            EXPECT_LE(f.stats.samples, ref.stats.samples) << to_string(k);
        }
    }
}

TEST(FrameRenderer, ReportsTfChangesBuildsAndSkippedSpace) {
    SyntheticOptions so;
    so.dims = {32, 32, 32};
    AccelOptions ao;
    ao.leaf_cells = 2;  // fine leaves, so the sphere's empty surroundings are skippable
    FrameRenderer fr(generate(SyntheticKind::Sphere, so), ao);
    ViewRequest req = request(AccelKind::None, "mr-default");
    Frame f = fr.render(req, 30, 30);
    EXPECT_TRUE(f.tf_changed);
    // No skipping, no early termination: every lattice sample is taken.
    EXPECT_GT(f.lattice_samples, 0u);
    EXPECT_EQ(f.stats.samples, f.lattice_samples);
    EXPECT_EQ(f.skipped, 0.0);

    f = fr.render(req, 30, 30);  // same TF: no change
    EXPECT_FALSE(f.tf_changed);
    EXPECT_EQ(f.tf_update_seconds, 0.0);

    req.accel = AccelKind::Bitfield;
    f = fr.render(req, 30, 30);
    EXPECT_FALSE(f.tf_changed);
    EXPECT_GT(f.accel_build_seconds, 0.0);  // built lazily, now
    // The sphere fills a fraction of its box: the structure skips a good part of the lattice.
    EXPECT_GT(f.skipped, 0.2);
    EXPECT_LT(f.skipped, 1.0);
    EXPECT_NEAR(double(f.stats.samples), double(f.lattice_samples) * (1.0 - f.skipped),
                1e-6 * double(f.lattice_samples));

    req.tf = preset("mr-brain");
    f = fr.render(req, 30, 30);
    EXPECT_TRUE(f.tf_changed);
    EXPECT_EQ(f.accel_build_seconds, 0.0);  // already built
    EXPECT_GT(f.tf_update_seconds, 0.0);
}

TEST(FrameRenderer, PanMovesTheImage) {
    SyntheticOptions so;
    so.dims = {20, 20, 20};
    FrameRenderer fr(generate(SyntheticKind::Sphere, so));
    ViewRequest req = request(AccelKind::None, "mr-default");
    const Frame centred = fr.render(req, 24, 24);
    req.camera.pan_x = 0.3f;
    const Frame panned = fr.render(req, 24, 24);
    EXPECT_NE(centred.image.rgba, panned.image.rgba);
    // A pan by zero is the unpanned camera exactly.
    req.camera.pan_x = 0.f;
    EXPECT_EQ(fr.render(req, 24, 24).image.rgba, centred.image.rgba);
}

TEST(FrameRenderer, HistogramCountsEveryVoxel) {
    SyntheticOptions so;
    so.dims = {17, 13, 11};
    Volume v = generate(SyntheticKind::SphereShells, so);
    // Brute force over the same bins.
    std::vector<uint64_t> expect(FrameRenderer::kHistogramBins, 0);
    const ValueRange r = v.vis_range();
    for (int k = 0; k < 11; ++k)
        for (int j = 0; j < 13; ++j)
            for (int i = 0; i < 17; ++i) {
                const double u = (double(v.value(i, j, k)) - r.min) *
                                 FrameRenderer::kHistogramBins / (double(r.max) - r.min);
                ++expect[size_t(std::clamp(int(u), 0, FrameRenderer::kHistogramBins - 1))];
            }
    FrameRenderer fr(std::move(v));
    EXPECT_EQ(fr.histogram(), expect);
}

TEST(Jpeg, EncodesABaselineJpegOfTheImageSize) {
    Image img(37, 21);
    for (int y = 0; y < 21; ++y)
        for (int x = 0; x < 37; ++x) {
            img.pixel(x, y)[0] = uint8_t(x * 6);
            img.pixel(x, y)[1] = uint8_t(y * 12);
            img.pixel(x, y)[3] = 255;
        }
    const std::string j = encode_jpeg(img, 80);
    ASSERT_GT(j.size(), 100u);
    EXPECT_EQ(uint8_t(j[0]), 0xFF);
    EXPECT_EQ(uint8_t(j[1]), 0xD8);  // SOI
    EXPECT_EQ(uint8_t(j[j.size() - 2]), 0xFF);
    EXPECT_EQ(uint8_t(j[j.size() - 1]), 0xD9);  // EOI
    // The SOF0 segment carries height and width.
    const size_t sof = j.find("\xFF\xC0");
    ASSERT_NE(sof, std::string::npos);
    EXPECT_EQ((uint8_t(j[sof + 5]) << 8) | uint8_t(j[sof + 6]), 21);
    EXPECT_EQ((uint8_t(j[sof + 7]) << 8) | uint8_t(j[sof + 8]), 37);
    EXPECT_THROW(encode_jpeg(Image(), 80), Error);
}
