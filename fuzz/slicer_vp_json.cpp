// 3D Slicer .vp.json files (docs/transfer-functions.md): every accepted VolumeProperty converts to
// a lacuna TF (or is rejected with lacuna::Error) and discretises.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "transfer/slicer_presets.h"

using namespace lacuna;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    return fuzz::guarded([&] {
        for (const SlicerVolumeProperty& p : parse_slicer_vp_json(text, "fuzz.vp.json")) {
            (void)to_string(p);
            try {
                discretise(to_transfer_function(p), ValueRange{0.f, 1.f}, 64);
            } catch (const Error&) {
            }
        }
    });
}
