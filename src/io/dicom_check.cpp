#include "io/dicom_check.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "lacuna/error.h"

namespace lacuna::io {

namespace {

// VRs whose explicit form has 2 reserved bytes and a 4-byte length (PS3.5 Section 7.1.2).
bool long_vr(const char* vr) {
    static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                  "SV", "UC", "UN", "UR", "UT", "UV"};
    for (const char* v : kLong)
        if (vr[0] == v[0] && vr[1] == v[1]) return true;
    return false;
}

std::string tag_text(uint16_t g, uint16_t e) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "(%04X,%04X)", g, e);
    return buf;
}

uint16_t u16(const uint8_t* p, bool big) {
    return big ? uint16_t(p[0] << 8 | p[1]) : uint16_t(p[1] << 8 | p[0]);
}
uint32_t u32(const uint8_t* p, bool big) {
    return big ? uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3]
               : uint32_t(p[3]) << 24 | uint32_t(p[2]) << 16 | uint32_t(p[1]) << 8 | p[0];
}

}  // namespace

DicomWalk walk_dicom_file(const std::string& file, const std::string& dir) {
    DicomWalk w;
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(file, ec);
    if (!in || ec || size < 132) return w;
    char magic[4] = {};
    in.seekg(128);
    in.read(magic, 4);
    if (std::memcmp(magic, "DICM", 4) != 0) return w;
    w.part10 = true;
    const std::string name = std::filesystem::path(file).filename().string();
    bool explicit_vr = true, big = false, in_meta = true;
    uint64_t pos = 132;
    std::string syntax;
    for (int n = 0; n < 100000 && pos + 8 <= size; ++n) {
        uint8_t h[12];
        in.seekg(std::streamoff(pos));
        in.read(reinterpret_cast<char*>(h), 8);
        if (in.gcount() != 8) return w;  // read error: left to GDCM
        const uint16_t g0 = u16(h, false);
        if (in_meta && g0 != 0x0002) {
            // The meta group ended: switch to the data set's transfer syntax (PS3.5 Annex A).
            in_meta = false;
            while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' '))
                syntax.pop_back();
            explicit_vr = syntax != "1.2.840.10008.1.2";
            big = syntax == "1.2.840.10008.1.2.2";
            if (syntax == "1.2.840.10008.1.2.1.99") return w;  // deflated: not walkable
        }
        const uint16_t g = u16(h, big), e = u16(h + 2, big);
        uint64_t len = 0, head = 8;
        const char vr[2] = {char(h[4]), char(h[5])};
        const bool has_vr =
            explicit_vr && vr[0] >= 'A' && vr[0] <= 'Z' && vr[1] >= 'A' && vr[1] <= 'Z';
        if (g == 0xFFFE) return w;  // item tags at top level: leave to GDCM
        if (has_vr && long_vr(vr)) {
            in.read(reinterpret_cast<char*>(h + 8), 4);
            if (in.gcount() != 4) {
                pos = size - 1;  // a long-VR header cut short
                break;
            }
            len = u32(h + 8, big);
            head = 12;
        } else if (has_vr) {
            len = u16(h + 6, big);
        } else {
            len = u32(h + 4, big);
        }
        if (len == 0xFFFFFFFFu) return w;  // undefined length: sequence or encapsulated pixels
        const uint64_t left = size - pos - head;
        if (len > left)
            throw Error(dir, name,
                        "element " + tag_text(g, e) + " says " + std::to_string(len) + " bytes, " +
                            std::to_string(left) +
                            " are left in the file (a damaged or truncated slice)");
        if (in_meta && g == 0x0002 && e == 0x0010 && len < 80) {
            syntax.resize(len);
            in.read(syntax.data(), std::streamsize(len));
        }
        // Elements after Pixel Data (padding, or junk) are walked too: GDCM reads them.
        if (g == 0x7FE0 && e == 0x0010) w.pixel_data_length = int64_t(len);
        pos += head + len;
    }
    // Bytes left over that cannot hold an element header: GDCM asserts on these
    // (gdcmExplicitDataElement.txx: Assertion '0 && "Should not happen"').
    if (pos < size)
        throw Error(dir, name,
                    "the file ends inside an element header at byte " + std::to_string(pos) +
                        " (a truncated slice)");
    if (in_meta)
        throw Error(dir, name,
                    "the file ends inside its file meta information (group 0002) at byte " +
                        std::to_string(pos) + " (a truncated slice)");
    return w;
}

}  // namespace lacuna::io
