// Session files (src/session/session_file.h): parse_session_file on arbitrary text. An accepted
// file must round-trip exactly (to_json, parse, to_json gives the same text) and its frame must
// pass lacuna::validate (the parser validates; a frame it accepts is one the renderers take).
#include "session/session_file.h"

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"

using namespace lacuna;
using fuzz::fuzz_check;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    return fuzz::guarded([&] {
        const SessionFile s = parse_session_file(text, "fuzz.json");
        const std::string json = to_json(s);
        fuzz_check(to_json(parse_session_file(json, "round trip")) == json, "to_json round trip",
                   json);
        validate(s.frame);
    });
}
