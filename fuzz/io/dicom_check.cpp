// fuzz_dicom_check: the walk of src/io/dicom_check.h alone, in process, on bytes in memory.
//
// fuzz_dicom_dir forks GDCM per input (about 50 execs/s), so it cannot reach 1 M execs in a
// day; what must hold before GDCM sees a file is this walk: it never crashes, hangs or reads
// out of bounds, and answers only with lacuna::Error, one line naming the file. Beyond that:
//   - the answer is consistent: "checked" implies "DICOM", "Part 10" is exactly "DICM" at 128,
//     a Pixel Data length fits in the file;
//   - "checked" means the elements tile the file to its last byte, so the same bytes with the
//     last one cut off must be an error (every decision before the last element reads the same
//     bytes; the last element then runs one byte past the end, or its header is cut).
#include "io/dicom_check.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "lacuna/error.h"

namespace {

const std::string kName = "slice.dcm", kDir = "/fuzz/series";

// The walk's answer, or nothing if it threw (the message checked).
bool walk(const uint8_t* data, size_t size, lacuna::io::DicomWalk& w) {
    try {
        w = lacuna::io::walk_dicom_bytes(data, size, kName, kDir);
        return true;
    } catch (const lacuna::Error& e) {
        const std::string m = e.what();
        if (m.find('\n') != std::string::npos || m.find(kName) == std::string::npos ||
            m.find(kDir) == std::string::npos) {
            std::fprintf(stderr, "fuzz: error not one line naming the file: %s\n", m.c_str());
            std::abort();
        }
        return false;
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    lacuna::io::DicomWalk w;
    if (!walk(data, size, w)) return 0;
    const bool dicm = size >= 132 && std::memcmp(data + 128, "DICM", 4) == 0;
    if ((w.checked && !w.dicom) || w.part10 != dicm || w.pixel_data_length > int64_t(size)) {
        std::fprintf(stderr, "fuzz: inconsistent walk: checked %d dicom %d part10 %d pixels %lld\n",
                     int(w.checked), int(w.dicom), int(w.part10),
                     static_cast<long long>(w.pixel_data_length));
        std::abort();
    }
    if (w.checked && size > 140) {
        lacuna::io::DicomWalk cut;
        if (walk(data, size - 1, cut)) {
            std::fprintf(stderr,
                         "fuzz: a checked file of %zu bytes passes cut by one (checked %d)\n", size,
                         int(cut.checked));
            std::abort();
        }
    }
    return 0;
}
