// fuzz_dicom_dir: the input is a folder of slices, concatenated with the separator below; each
// piece becomes slice_<n>.dcm in a fresh folder, which read_volume reads as a DICOM series.
//
// GDCM runs in a child process (src/io/isolated.h). A child killed by a signal is GDCM dying
// on a damaged file, which the reader reports as an error: the design under test. A child that
// exits non-zero without an error message is a sanitizer report in the child (ASan and UBSan
// exit with code 1): a finding, so the harness aborts. To see the report, rerun the input with
// LACUNA_CHILD_STDERR=1 (the child then keeps stderr).
#include <string>

#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    static const std::string_view kSep("--lacuna-slice--");
    const std::string dir = scratch_dir("dicom_dir") + "/series";
    std::filesystem::create_directory(dir);
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    for (int n = 0; n < 16 && !rest.empty(); ++n) {
        const auto [slice, tail] = split(rest, kSep);
        put(dir, "slice_" + std::to_string(n) + ".dcm", slice);
        rest = tail;
    }
    try {
        read_volume(dir, fuzz_options());
    } catch (const lacuna::Error& e) {
        const std::string m = e.what();
        if (m.find('\n') != std::string::npos || m.find("(GDCM) failed") != std::string::npos) {
            std::fprintf(stderr, "fuzz: %s\n", m.c_str());
            std::abort();
        }
    }
    return 0;
}
