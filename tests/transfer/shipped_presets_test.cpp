// presets/*.json are the built-in presets in our JSON format (docs/transfer-functions.md).
// After changing a built-in preset, regenerate them with
//     LACUNA_REGENERATE_PRESETS=1 ./build/lacuna_tests --gtest_filter='ShippedPresets.*'
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "lacuna/transfer_function.h"

namespace lacuna {
namespace {

TEST(ShippedPresets, EachFileReadsBackEqualToTheBuiltIn) {
    const std::string dir = std::string(LACUNA_SOURCE_DIR) + "/presets/";
    const bool regenerate = std::getenv("LACUNA_REGENERATE_PRESETS") != nullptr;
    ASSERT_EQ(preset_names().size(), 16u);
    for (const std::string& name : preset_names()) {
        // 3D Slicer's (value domain, capitalised) live in presets/slicer/: "CT-Bone.json" beside
        // "ct-bone.json" would be one file on a case-insensitive file system.
        const bool slicer = preset(name).domain == TfDomain::Value;
        const std::string path = dir + (slicer ? "slicer/" : "") + name + ".json";
        if (regenerate) std::ofstream(path) << to_json(preset(name));
        const TransferFunction shipped = load_transfer_function(path);
        EXPECT_EQ(shipped, preset(name)) << path << " should read:\n" << to_json(preset(name));
        // And through --tf resolution, by path.
        EXPECT_EQ(resolve_transfer_function(path), preset(name)) << path;
    }
}

}  // namespace
}  // namespace lacuna
