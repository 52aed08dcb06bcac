// 3D Slicer .vp files (docs/transfer-functions.md): an accepted property converts to a
// lacuna TF (or is rejected with lacuna::Error) and discretises.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "transfer/slicer_presets.h"

using namespace lacuna;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    return fuzz::guarded([&] {
        const std::vector<SlicerVolumeProperty> props{parse_slicer_vp(text, "fuzz.vp")};
        for (const SlicerVolumeProperty& p : props) {
            (void)to_string(p);
            try {
                discretise(to_transfer_function(p), ValueRange{0.f, 1.f}, 64);
            } catch (const Error&) {
            }
        }
    });
}
