// --tf with 3D Slicer presets end to end: the imported preset renders the same bytes as the same
// TF written in lacuna's JSON, and every malformed entry is one line and exit code 2.
#include "apps/cli_run.h"

namespace lacuna::test {
namespace {

const std::string kData = std::string(LACUNA_SOURCE_DIR) + "/tests/data/";

const std::filesystem::path& dir() {
    static const std::filesystem::path d = cli_temp_dir("slicer");
    return d;
}

// A CT-like volume: int16 sphere shells span -1024..3071.
const std::string& ct_volume() {
    static const std::string v = [] {
        const std::string p = (dir() / "shells-ct.nrrd").string();
        const CliResult r =
            run_cli("generate sphere-shells --type int16 --dims 30x28x26 --out " + p, dir());
        EXPECT_EQ(r.code, 0) << r.err;
        return p;
    }();
    return v;
}

std::string render(const std::string& tf, const std::string& name, const std::string& extra = "") {
    const std::string png = (dir() / (name + ".png")).string();
    const CliResult r = run_cli(
        "render " + ct_volume() + " --tf '" + tf + "' --size 40 " + extra + " --out " + png, dir());
    EXPECT_EQ(r.code, 0) << tf << ": " << r.err;
    return slurp_file(png);
}

TEST(CliSlicerPresets, ImportedPresetRendersLikeOurJson) {
    const std::string ours = render(kData + "lacuna-ct-bone-value.json", "ours");
    ASSERT_FALSE(ours.empty());
    EXPECT_EQ(render("slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone", "xml"), ours);
    EXPECT_EQ(render(kData + "lacuna-ct.vp.json", "vpjson"), ours);
    EXPECT_EQ(
        render("slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone", "xml-kd", "--accel kdtree"),
        ours);
    // And it shows something: a different preset gives other bytes.
    EXPECT_NE(render(kData + "lacuna-mr.vp", "vp"), ours);
}

TEST(CliSlicerPresets, MalformedFilesAreOneLineErrors) {
    struct Case {
        std::string file, text, needle;
    };
    const std::string good_rest = " colorTransfer=\"8 0 0 0 0 255 1 1 1\"/>\n</MRML>\n";
    const Case cases[] = {
        {"count.xml",
         "<MRML>\n<VolumeProperty name=\"A\" scalarOpacity=\"6 0 0 255 1\"" + good_rest,
         "count.xml: VolumeProperty \"A\" (line 2): scalarOpacity: expected 6 numbers after the "
         "count, got 4"},
        {"alpha.xml",
         "<MRML>\n<VolumeProperty name=\"A\" scalarOpacity=\"4 0 0 255 7\"" + good_rest,
         "alpha.xml: VolumeProperty \"A\" (line 2): scalarOpacity[1]: expected opacity in [0,1], "
         "got 7"},
        {"noop.xml", "<MRML>\n<VolumeProperty name=\"A\"" + good_rest,
         "noop.xml: VolumeProperty \"A\" (line 2): scalarOpacity: missing"},
        {"broken.xml", "<MRML>\n<VolumeProperty name=\"A\"\n",
         "broken.xml: xml: not well-formed XML"},
        {"range.xml",
         "<MRML>\n<VolumeProperty name=\"A\" effectiveRange=\"9 1\" scalarOpacity=\"4 0 0 255 1\"" +
             good_rest,
         "range.xml: VolumeProperty \"A\" (line 2): effectiveRange: expected two finite numbers lo "
         "< hi"},
        {"short.vp", "1\n1\n0.9\n", "short.vp: lines: expected 9 lines"},
        {"mid.vp.json",
         "{\"volumeProperties\": [{\"components\": [{\"scalarOpacity\": {\"points\": [{\"x\": 0, "
         "\"y\": 0, "
         "\"midpoint\": 0.2, \"sharpness\": 0}]}}]}]}",
         "mid.vp.json: volumeProperties[0].components[0].scalarOpacity.points[0]: expected "
         "midpoint 0.5"},
    };
    for (const Case& c : cases) {
        const std::string path = (dir() / c.file).string();
        std::ofstream(path) << c.text;
        const std::string spec = c.file.ends_with(".xml") ? "slicer:" + path + "#A" : path;
        const std::string png = (dir() / "never.png").string();
        const CliResult r =
            run_cli("render " + ct_volume() + " --tf '" + spec + "' --size 16 --out " + png, dir());
        expect_one_line_error(r, c.needle);
        EXPECT_FALSE(std::filesystem::exists(png)) << c.file;
    }
    expect_one_line_error(
        run_cli("render " + ct_volume() + " --tf 'slicer:" + kData +
                    "slicer-presets.xml#CT-Bone' --out " + (dir() / "x.png").string(),
                dir()),
        "preset: unknown 'CT-Bone'; expected one of: Lacuna-CT-Bone, Lacuna-MR-Brain, Lacuna-Step");
}

}  // namespace
}  // namespace lacuna::test
