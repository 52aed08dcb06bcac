// fuzz_nifti_frames: 4D NIfTI read volume by volume (ReadOptions::frame) and two-file pairs.
// Byte 0 picks the files and the frame: bits 0-1 the files (0: x.nii without a frame, 1: x.nii,
// 2: x.hdr + x.img, 3: x.hdr + x.img.gz compressed here), bits 2-7 the frame (0..63). A pair's
// .hdr is the rest's first 348 bytes, or 540 when its first word says NIfTI-2 (either byte
// order); its .img is the remainder. Each pair is read by both names.
#include <zlib.h>

#include <cstring>

#include "reader_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lacuna::fuzz_io;
    if (size < 1) return 0;
    const int files = data[0] & 3;
    lacuna::ReadOptions o = fuzz_options();
    if (files != 0) o.frame = data[0] >> 2;
    const std::string dir = scratch_dir("nifti_frames");
    const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
    if (files < 2) {
        read_expecting_errors(put(dir, "x.nii", rest), o);
        return 0;
    }
    size_t split = 348;
    if (rest.size() >= 4) {
        uint8_t w[4];
        std::memcpy(w, rest.data(), 4);
        if ((w[0] == 0x1c && w[1] == 0x02 && !w[2] && !w[3]) ||
            (!w[0] && !w[1] && w[2] == 0x02 && w[3] == 0x1c))
            split = 540;
    }
    split = std::min(split, rest.size());
    put(dir, "x.hdr", rest.substr(0, split));
    const std::string_view img = rest.substr(split);
    if (files == 2) {
        put(dir, "x.img", img);
    } else {
        gzFile f = gzopen((dir + "/x.img.gz").c_str(), "wb1");
        if (!f) return 0;
        if (!img.empty()) gzwrite(f, img.data(), unsigned(img.size()));
        gzclose(f);
    }
    read_expecting_errors(dir + "/x.hdr", o);
    read_expecting_errors(dir + (files == 2 ? "/x.img" : "/x.img.gz"), o);
    return 0;
}
