// fuzz_nifti: the input is a .nii file (NIfTI-1 or NIfTI-2, plain).
#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    const std::string dir = scratch_dir("nifti");
    read_expecting_errors(put(dir, "x.nii", {reinterpret_cast<const char*>(data), size}));
    return 0;
}
