// TF JSON (docs/transfer-functions.md): parse_transfer_function on arbitrary text. An accepted TF
// must round-trip exactly through to_json, discretise into a LUT of finite entries in [0,1],
// and its map must give an entry in range at both ends of its range and beyond.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "lacuna/transfer_function.h"

using namespace lacuna;
using fuzz::fuzz_check;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    return fuzz::guarded([&] {
        const TransferFunction tf = parse_transfer_function(text, "fuzz.json");
        const std::string json = to_json(tf);
        fuzz_check(parse_transfer_function(json, "round trip") == tf, "to_json round trip", json);
        const TransferLut lut = discretise(tf, ValueRange{0.f, 1.f}, 64);
        for (const Rgba& c : lut.entries)
            for (float x : {c.r, c.g, c.b, c.a})
                fuzz_check(std::isfinite(x) && x >= 0.f && x <= 1.f, "LUT entry in [0,1]",
                           to_string(c));
        const ValueToLut map = lut.map();
        for (float v : {lut.vis.min, lut.vis.max, -3e38f, 3e38f, 0.f}) {
            const int e = map(v);
            fuzz_check(e >= 0 && e < lut.size(), "map entry in range", std::to_string(e));
        }
    });
}
