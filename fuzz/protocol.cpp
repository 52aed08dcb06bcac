// The viewer's WebSocket messages (src/serve/protocol.h): parse_request and request_id on
// arbitrary text, with the server's default limits. What the server does next with an accepted
// request is done here too, short of rendering: the TF discretised over a volume's range, its
// map evaluated, the "hide" list applied to a label table, the error answer built for a rejected
// message (valid JSON for any bytes the message echoes).
#include "serve/protocol.h"

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "fuzz_util.h"
#include "lacuna/segments.h"

using namespace lacuna;
using fuzz::fuzz_check;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const serve::Limits limits;
    (void)serve::request_id(text, limits);
    try {
        const serve::ViewRequest req = serve::parse_request(text, limits);
        fuzz_check(req.width >= 1 && req.width <= limits.max_side && req.height >= 1 &&
                       req.height <= limits.max_side,
                   "image size within limits",
                   std::to_string(req.width) + "x" + std::to_string(req.height));
        const TransferLut lut = discretise(req.tf, ValueRange{-1024.f, 3071.f});
        const ValueToLut map = lut.map();
        for (float v : {lut.vis.min, lut.vis.max, -3e38f, 3e38f, 0.f}) {
            const int e = map(v);
            fuzz_check(e >= 0 && e < lut.size(), "map entry in range", std::to_string(e));
        }
        if (!req.hide.empty()) {
            LabelTable t;
            t.styles.resize(64);
            set_label_visibility(t, req.hide, false, "hide");
        }
    } catch (const Error& e) {
        const std::string answer = serve::error_message(e.what(), serve::request_id(text, limits));
        fuzz_check(nlohmann::json::accept(answer), "error answer is JSON", answer);
    }
    return 0;
}
