#include "io/dicom_check.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "lacuna/error.h"

namespace lacuna::io {

namespace {

// Reads up to n bytes at pos into buf; returns how many it read (fewer at the end of the file).
using ReadAt = std::function<size_t(uint64_t pos, uint8_t* buf, size_t n)>;

// VRs whose explicit form has 2 reserved bytes and a 4-byte length (PS3.5 Section 7.1.2).
bool long_vr(const char* vr) {
    static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ",
                                  "SV", "UC", "UN", "UR", "UT", "UV"};
    for (const char* v : kLong)
        if (vr[0] == v[0] && vr[1] == v[1]) return true;
    return false;
}

// What GDCM's VR::GetVRType does not answer VR_END for, when it guesses the encoding of a file
// without a file meta group (FileMetaInformation::ReadCompat): the VRs of PS3.5 Table 6.2-1
// and "??" (GDCM 3.0.21's VRStrings, whose entry 0 is "??", VR::INVALID).
bool known_vr(const uint8_t* p) {
    static const char* kVr[] = {"??", "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FD",
                                "FL", "IS", "LO", "LT", "OB", "OD", "OF", "OL", "OV",
                                "OW", "PN", "SH", "SL", "SQ", "SS", "ST", "SV", "TM",
                                "UC", "UI", "UL", "UN", "UR", "US", "UT", "UV"};
    for (const char* v : kVr)
        if (char(p[0]) == v[0] && char(p[1]) == v[1]) return true;
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

// How a data set is encoded.
struct Encoding {
    bool explicit_vr = true, big = false;
};

// How many (0000,0000) elements may open a data set before the walk refuses it (see below).
constexpr int kMaxNullElements = 16;

// GDCM's guess for a data set that starts at byte `base` without a file meta group:
// FileMetaInformation::ReadCompat of GDCM 3.0.21 (Debian 12's), branch by branch, checked
// against its source. False when GDCM gives up on the file ("Cannot find DICOM type", "Cannot
// read very first tag") or reads no value of it (implicit big endian, which GDCM refuses).
//
// One branch calls ReadCompat again: a first element (0000,0000) in implicit VR with a length
// of 4 (GDCM's comment: "something like IM-0001-0066.CommandTag00.dcm was crafted"). GDCM reads
// its value, guesses from the element after it, then `assert(DataSetTS ==
// ImplicitVRLittleEndian)`, seeks back to the (0000,0000) and reads the data set from there.
// Debian's GDCM keeps its asserts (finding 2 of "Readers" in docs/reliability.md was one), so
// every other answer of the second guess aborts GDCM: a group 0002 meta group after it, any
// explicit VR, group 0800 (big endian either way). The walk follows the same chain: an answer
// other than implicit little endian is refused here with one line (before, it was walked as
// implicit and left to abort GDCM in the reader's child, which the parent reports as GDCM
// dying); a second guess that gives up means GDCM gives up on the file; and each further
// (0000,0000) is one more recursive call, so a data set opening with more than
// kMaxNullElements of them (a real file has at most one) is refused too, long before GDCM's
// stack would run out (a few hundred bytes of frame per 12-byte element).
bool guess_encoding(const ReadAt& read, uint64_t base, Encoding& enc, const std::string& name,
                    const std::string& dir) {
    uint8_t h[8];
    for (int nulls = 0;; ++nulls) {
        const uint64_t pos = base + uint64_t(nulls) * 12;
        const size_t got = read(pos, h, 8);
        if (got < 4) return false;  // "Cannot read very first tag"
        const uint16_t g = u16(h, false), e = u16(h + 2, false);
        const bool vr = got >= 6 && known_vr(h + 4);
        const auto refuse = [&](const std::string& what) {
            throw Error(dir, name,
                        "starts with element (0000,0000) followed by " + what + " at byte " +
                            std::to_string(pos) +
                            " (GDCM asserts that such a data set is implicit VR little "
                            "endian: a crafted file)");
        };
        // (A meta group at `base` itself is the walk's, before any guess.)
        if (g == 0x0002 && nulls > 0) refuse("a file meta group element " + tag_text(g, e));
        if (g == 0x0008) {
            enc = {vr, false};
        } else if (g == 0x0800) {  // ACR-NEMA big endian
            if (nulls > 0)
                refuse("a big-endian element " + tag_text(u16(h, true), u16(h + 2, true)));
            if (!vr) return false;
            enc = {true, true};
        } else if (e == 0x0010) {  // a private creator first: little endian
            enc = {vr, false};
        } else if (vr) {
            enc = {true, g > 0xFF || e > 0xFF};
        } else if (g == 0 && e == 0 && got >= 8 && u32(h + 4, false) == 4) {
            // (0000,0000) of 4 bytes: its value, then GDCM guesses again from the next element.
            // A value cut short leaves GDCM's stream failed (its next guess asserts on that):
            // walked as implicit, the walk reports that element's length.
            uint8_t value[4];
            if (read(pos + 8, value, 4) != 4) {
                enc = {false, false};
                return true;
            }
            if (nulls + 1 > kMaxNullElements)
                throw Error(dir, name,
                            "starts with more than " + std::to_string(kMaxNullElements) +
                                " elements (0000,0000) (GDCM reads each one recursively: a "
                                "crafted file)");
            continue;
        } else {
            return false;  // "Cannot find DICOM type. Giving up."
        }
        if (nulls > 0 && (enc.explicit_vr || enc.big))
            refuse("an explicit-VR element " + tag_text(g, e));
        return true;
    }
}

// At most this many top-level elements: a real slice has hundreds, a file of empty elements
// would keep the walk busy for nothing.
constexpr int kMaxElements = 1 << 20;

DicomWalk walk(const ReadAt& read, uint64_t size, const std::string& name, const std::string& dir) {
    DicomWalk w;
    uint8_t h[12];
    uint64_t pos = 0;
    if (size >= 132 && read(128, h, 4) == 4 && std::memcmp(h, "DICM", 4) == 0) {
        w.part10 = true;
        pos = 132;
    }
    // Where GDCM starts: a file meta group (group 0002, after "DICM" or at byte 0), or a data
    // set whose encoding it guesses from the first tag.
    Encoding enc;
    bool in_meta = w.part10;
    const size_t got = read(pos, h, 8);
    if (got >= 4 && u16(h, false) == 0x0002) {
        in_meta = true;
    } else if (got >= 4 || !w.part10) {
        // A Part 10 file with no meta group, or no preamble: GDCM's guess (ReadCompat).
        if (!guess_encoding(read, pos, enc, name, dir)) return w;
        in_meta = false;
    }
    w.dicom = true;
    std::string syntax;
    int n = 0;
    for (; n < kMaxElements && pos + 8 <= size; ++n) {
        if (read(pos, h, 8) != 8) return w;  // read error: left to GDCM
        const uint16_t g0 = u16(h, false);
        if (in_meta && g0 != 0x0002) {
            // The meta group ended: switch to the data set's transfer syntax (PS3.5 Annex A).
            in_meta = false;
            while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' '))
                syntax.pop_back();
            enc.explicit_vr = syntax != "1.2.840.10008.1.2";
            enc.big = syntax == "1.2.840.10008.1.2.2";
            if (syntax == "1.2.840.10008.1.2.1.99") return w;  // deflated: not walkable
        }
        const uint16_t g = u16(h, enc.big), e = u16(h + 2, enc.big);
        uint64_t len = 0, head = 8;
        const char vr[2] = {char(h[4]), char(h[5])};
        const bool has_vr =
            enc.explicit_vr && vr[0] >= 'A' && vr[0] <= 'Z' && vr[1] >= 'A' && vr[1] <= 'Z';
        if (g == 0xFFFE) return w;  // item tags at top level: leave to GDCM
        if (has_vr && long_vr(vr)) {
            if (read(pos + 8, h + 8, 4) != 4) {
                pos = size - 1;  // a long-VR header cut short
                break;
            }
            len = u32(h + 8, enc.big);
            head = 12;
        } else if (has_vr) {
            len = u16(h + 6, enc.big);
        } else {
            len = u32(h + 4, enc.big);
        }
        if (len == 0xFFFFFFFFu) return w;  // undefined length: sequence or encapsulated pixels
        const uint64_t left = size - pos - head;
        if (len > left)
            throw Error(dir, name,
                        "element " + tag_text(g, e) + " says " + std::to_string(len) + " bytes, " +
                            std::to_string(left) + " are left in the file (a damaged or " +
                            (w.part10 ? "truncated slice)"
                                      : "truncated slice, read without a DICOM preamble)"));
        if (in_meta && g == 0x0002 && e == 0x0010 && len < 80) {
            syntax.resize(len);
            syntax.resize(read(pos + head, reinterpret_cast<uint8_t*>(syntax.data()), len));
        }
        // Elements after Pixel Data (padding, or junk) are walked too: GDCM reads them.
        if (g == 0x7FE0 && e == 0x0010) w.pixel_data_length = int64_t(len);
        pos += head + len;
    }
    if (n == kMaxElements && pos < size)
        throw Error(dir, name,
                    "has more than " + std::to_string(kMaxElements) +
                        " top-level elements (expected a DICOM slice)");
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
    w.checked = true;
    return w;
}

}  // namespace

DicomWalk walk_dicom_file(const std::string& file, const std::string& dir) {
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(file, ec);
    if (!in || ec) return DicomWalk{};  // unreadable: GDCM cannot read it either
    const ReadAt read = [&](uint64_t pos, uint8_t* buf, size_t n) -> size_t {
        in.clear();
        in.seekg(std::streamoff(pos));
        in.read(reinterpret_cast<char*>(buf), std::streamsize(n));
        return size_t(std::max<std::streamsize>(in.gcount(), 0));
    };
    return walk(read, size, std::filesystem::path(file).filename().string(), dir);
}

DicomWalk walk_dicom_bytes(const uint8_t* data, size_t size, const std::string& name,
                           const std::string& dir) {
    const ReadAt read = [&](uint64_t pos, uint8_t* buf, size_t n) -> size_t {
        if (pos >= size) return 0;
        const size_t k = std::min<uint64_t>(n, size - pos);
        std::memcpy(buf, data + pos, k);
        return k;
    };
    return walk(read, size, name, dir);
}

}  // namespace lacuna::io
