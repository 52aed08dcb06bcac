// `lacuna render --tf` with a TF that carries a rendering (3D Slicer's shade, ambient, diffuse,
// specular, specular power and gradient opacity; a MIP preset's blend): the frame is the one the
// explicit flags give (docs/transfer-functions.md, "The TF's rendering"), every flag given wins,
// and every built-in Slicer preset renders something.
//
// The reference of each comparison is the same TF with its rendering removed, written to a file,
// plus the flags the rule says the rendering stands for: so a test fails if the rule maps a term
// wrongly, drops one, or applies where a flag was given.
#include <array>

#include "apps/cli_run.h"
#include "lacuna/image.h"
#include "lacuna/transfer_function.h"

namespace lacuna::test {
namespace {

const std::string kData = std::string(LACUNA_SOURCE_DIR) + "/tests/data/";

const std::filesystem::path& dir() {
    static const std::filesystem::path d = cli_temp_dir("tf-rendering");
    return d;
}

// int16 sphere shells, -1024..3071 (CT-like), and uint8 ones, 0..255 (MR-like).
const std::string& volume(bool ct) {
    static const std::array<std::string, 2> v = [] {
        std::array<std::string, 2> out;
        for (int i = 0; i < 2; ++i) {
            out[i] = (dir() / (i ? "shells-ct.nrrd" : "shells-mr.nrrd")).string();
            const CliResult r =
                run_cli(std::string("generate sphere-shells --type ") + (i ? "int16" : "uint8") +
                            " --dims 30x28x26 --out " + out[i],
                        dir());
            EXPECT_EQ(r.code, 0) << r.err;
        }
        return out;
    }();
    return v[ct ? 1 : 0];
}

std::string render(const std::string& tf, bool ct, const std::string& extra,
                   const std::string& name) {
    const std::string png = (dir() / (name + ".png")).string();
    std::filesystem::remove(png);
    const CliResult r = run_cli("render " + volume(ct) + " --tf '" + tf +
                                    "' --size 40 --accel bitfield " + extra + " --out " + png,
                                dir());
    EXPECT_EQ(r.code, 0) << tf << " " << extra << ": " << r.err;
    return slurp_file(png);
}

// The TF of `spec` without its rendering, as a JSON file.
std::string bare(const std::string& spec, const std::string& name) {
    TransferFunction tf = resolve_transfer_function(spec);
    EXPECT_FALSE(tf.rendering.empty()) << spec;
    tf.rendering = {};
    const std::string path = (dir() / (name + ".json")).string();
    std::ofstream(path) << to_json(tf);
    return path;
}

TEST(CliTfRendering, ShadedSlicerPresetEqualsExplicitPhongWithItsTerms) {
    // Lacuna-CT-Bone: shade="1" ambient 0.15 diffuse 0.8 specular 0.3 specularPower 20.
    const std::string xml = "slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone";
    const std::string plain = bare(xml, "ct-bone-bare");
    const std::string shaded = render(xml, true, "", "xml");
    ASSERT_FALSE(shaded.empty());
    EXPECT_EQ(shaded, render(plain, true, "--shading phong --phong 0.15,0.8,0.3,20", "explicit"));
    EXPECT_NE(shaded, render(plain, true, "", "flat"));  // the shading is really on
    // The same property as .vp.json and as lacuna JSON (which writes the terms too).
    EXPECT_EQ(render(kData + "lacuna-ct.vp.json", true, "", "vpjson"), shaded);
    EXPECT_EQ(render(kData + "lacuna-ct-bone-value.json", true, "", "ours"), shaded);
}

TEST(CliTfRendering, ExplicitFlagsOverrideThePresetsDefaults) {
    const std::string xml = "slicer:" + kData + "slicer-presets.xml#Lacuna-CT-Bone";
    const std::string plain = bare(xml, "ct-bone-bare2");
    // --shading none: flat, as the bare TF.
    EXPECT_EQ(render(xml, true, "--shading none", "none"), render(plain, true, "", "flat2"));
    // --phong alone: the model from the preset, the user's terms.
    EXPECT_EQ(render(xml, true, "--phong 0.3,0.5,0.6,5", "terms"),
              render(plain, true, "--shading phong --phong 0.3,0.5,0.6,5", "terms-explicit"));
    // --shading pbr: the user's model.
    EXPECT_EQ(render(xml, true, "--shading pbr", "pbr"),
              render(plain, true, "--shading pbr", "pbr-explicit"));
}

TEST(CliTfRendering, SlicerGradientOpacityIsAppliedUnlessGiven) {
    // Lacuna-MR-Brain: shade="0", gradientOpacity="6 0 0.5 20 1 255 1".
    const std::string xml = "slicer:" + kData + "slicer-presets.xml#Lacuna-MR-Brain";
    const std::string plain = bare(xml, "mr-brain-bare");
    const std::string go = render(xml, false, "", "go");
    EXPECT_EQ(go, render(plain, false, "--gradient-opacity 0:0.5,20:1,255:1", "go-explicit"));
    EXPECT_NE(go, render(plain, false, "", "go-flat"));
    EXPECT_EQ(render(xml, false, "--gradient-opacity none", "go-none"),
              render(plain, false, "", "go-flat2"));
    EXPECT_EQ(render(xml, false, "--gradient-opacity 5,50", "go-ramp"),
              render(plain, false, "--gradient-opacity 5,50", "go-ramp-explicit"));
}

TEST(CliTfRendering, MipPresetsBlendByMaximumUnlessGiven) {
    // CT-MIP: shade="1" (0.1, 0.9, 0.2, 10) and blend "mip"; MIP takes no shading.
    const std::string plain = bare("CT-MIP", "ct-mip-bare");
    const std::string mip = render("CT-MIP", true, "", "mip");
    EXPECT_EQ(mip, render(plain, true, "--blend mip", "mip-explicit"));
    EXPECT_EQ(render("CT-MIP", true, "--blend composite", "mip-composite"),
              render(plain, true, "--shading phong --phong 0.1,0.9,0.2,10", "composite-explicit"));
    EXPECT_NE(mip, render(plain, true, "", "mip-flat"));
}

TEST(CliTfRendering, EveryBuiltInSlicerPresetLoadsAndRendersSomething) {
    for (const char* name : {"CT-AAA", "CT-Bone", "CT-Lung", "CT-Soft-Tissue", "CT-MIP",
                             "MR-Default", "MR-Angio", "MR-MIP"}) {
        const bool ct = std::string(name).starts_with("CT");
        const std::string png = (dir() / (std::string("preset-") + name + ".png")).string();
        const CliResult r =
            run_cli("render " + volume(ct) + " --tf " + name + " --size 40 --out " + png, dir());
        ASSERT_EQ(r.code, 0) << name << ": " << r.err;
        const Image img = read_png(png);
        int lit = 0;
        for (size_t i = 0; i < img.rgba.size(); i += 4)
            lit += img.rgba[i] + img.rgba[i + 1] + img.rgba[i + 2] > 0;
        EXPECT_GT(lit, 40) << name << ": " << lit << " of 1600 pixels lit";
        // The shaded ones say so.
        if (preset(name).rendering.shading && !preset(name).rendering.blend)
            EXPECT_NE(r.out.find("shading phong"), std::string::npos) << name << ": " << r.out;
    }
}

}  // namespace
}  // namespace lacuna::test
