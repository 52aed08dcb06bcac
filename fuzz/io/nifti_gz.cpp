// fuzz_nifti_gz: .nii.gz. Byte 0 picks how the rest becomes the file: even, the rest is
// gzip-compressed here (mutations reach the header through the compression); odd, the rest is
// the .nii.gz file as is (mutations reach the gzip container: truncation, CRC, bad blocks).
#include <zlib.h>

#include <vector>

#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    if (size < 1) return 0;
    const std::string dir = scratch_dir("nifti_gz");
    const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
    const std::string path = dir + "/x.nii.gz";
    if (data[0] & 1) {
        put(dir, "x.nii.gz", rest);
    } else {
        gzFile f = gzopen(path.c_str(), "wb1");
        if (!f) return 0;
        if (!rest.empty()) gzwrite(f, rest.data(), unsigned(rest.size()));
        gzclose(f);
    }
    read_expecting_errors(path);
    return 0;
}
