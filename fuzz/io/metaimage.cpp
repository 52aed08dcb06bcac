// fuzz_metaimage: byte 0 picks the layout: even, the rest is an attached .mha; odd, a detached
// .mhd and its data, split at the first NUL byte into x.mhd and x.raw.
#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    if (size < 1) return 0;
    const std::string dir = scratch_dir("metaimage");
    const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
    if (data[0] & 1) {
        const auto [header, body] = split(rest, std::string_view("\0", 1));
        put(dir, "x.raw", body);
        read_expecting_errors(put(dir, "x.mhd", header));
    } else {
        read_expecting_errors(put(dir, "x.mha", rest));
    }
    return 0;
}
