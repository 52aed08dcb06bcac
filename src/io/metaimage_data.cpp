// MetaImage voxel data, read by our code after ITK has parsed the header.
//
// Why: MetaIO (ITK 5.2) accepts short or corrupt voxel data silently — it prints a complaint to
// std::cerr and returns success, leaving the buffer partly unwritten. Reading the data here
// lets truncation and corrupt compression become errors, and converts types through a small
// staging buffer instead of a full-size temporary.
//
// Layouts handled: "ElementDataFile = LOCAL" (data follows the header line in the same file)
// and one external data file, raw or zlib/gzip-compressed, with HeaderSize skip (-1 = data at
// the end of the file). Slice lists and file-name patterns are left to MetaIO.
#include "io/metaimage_data.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "io/detached_data.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace {

namespace fs = std::filesystem;

// Offset of the first byte after the "ElementDataFile = LOCAL" line, or -1.
int64_t local_data_offset(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::string head(size_t(1) << 20, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    size_t pos = 0;
    while (pos < head.size()) {
        const size_t eol = head.find('\n', pos);
        if (eol == std::string::npos) return -1;
        const size_t key = head.find_first_not_of(" \t", pos);
        if (key != std::string::npos && key < eol && head.compare(key, 15, "ElementDataFile") == 0)
            return int64_t(eol + 1);
        pos = eol + 1;
    }
    return -1;
}

// Streams inflated bytes out of a zlib or gzip stream.
class Inflater {
  public:
    Inflater(std::ifstream& in, const std::string& where) : m_in(in), m_where(where) {
        if (inflateInit2(&m_z, 15 + 32) != Z_OK)  // +32: accept zlib and gzip headers
            throw Error(where, "voxel data", "cannot initialise zlib");
    }
    ~Inflater() { inflateEnd(&m_z); }
    Inflater(const Inflater&) = delete;
    Inflater& operator=(const Inflater&) = delete;

    size_t read(void* out, size_t n) {
        m_z.next_out = static_cast<Bytef*>(out);
        m_z.avail_out = uInt(n);  // callers ask for at most 64 MiB at a time
        while (m_z.avail_out > 0 && !m_done) {
            if (m_z.avail_in == 0) {
                m_in.read(reinterpret_cast<char*>(m_buf.data()), std::streamsize(m_buf.size()));
                m_z.next_in = m_buf.data();
                m_z.avail_in = uInt(m_in.gcount());
                if (m_z.avail_in == 0) break;  // compressed stream cut short
            }
            const int rc = inflate(&m_z, Z_NO_FLUSH);
            if (rc == Z_STREAM_END) {
                m_done = true;
            } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
                throw Error(m_where, "voxel data",
                            std::string("corrupt compressed data: ") +
                                (m_z.msg ? m_z.msg : "zlib error " + std::to_string(rc)));
            }
        }
        return n - m_z.avail_out;
    }

  private:
    std::ifstream& m_in;
    std::string m_where;
    z_stream m_z{};
    std::vector<Bytef> m_buf = std::vector<Bytef>(size_t(1) << 20);
    bool m_done = false;
};

// The header fields that hold the index-to-world map (MetaIO's names and synonyms).
bool geometry_key(const std::string& key) {
    for (const char* k : {"TransformMatrix", "Rotation", "Orientation", "Offset", "Position",
                          "Origin", "CenterOfRotation", "ElementSpacing", "ElementSize"})
        if (key == k) return true;
    return false;
}

std::vector<std::string> split_words(const std::string& s) {
    std::vector<std::string> out;
    size_t at = 0;
    while ((at = s.find_first_not_of(" \t", at)) != std::string::npos) {
        const size_t end = std::min(s.find_first_of(" \t", at), s.size());
        out.push_back(s.substr(at, end - at));
        at = end;
    }
    return out;
}

}  // namespace

MetaHeaderOrientation check_metaimage_header(const std::string& path) {
    MetaHeaderOrientation orientation;
    // Headers are a few hundred bytes: look at the first MiB, up to ElementDataFile (the last
    // key). MetaIO parses on past where we stop, so a header without ElementDataFile there is
    // rejected here rather than parsed by MetaIO unchecked.
    constexpr size_t kWindow = size_t(1) << 20;
    constexpr size_t kMaxField = 254;  // MetaIO strcpy()s keys and values into char[255]
    std::ifstream in(path, std::ios::binary);
    std::string head(kWindow, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    const auto trim = [](std::string t) {
        t.erase(t.find_last_not_of(" \t\r") + 1);
        t.erase(0, t.find_first_not_of(" \t"));
        return t;
    };
    for (size_t pos = 0, n = 1; pos < head.size(); ++n) {
        const size_t eol = std::min(head.find('\n', pos), head.size());
        const std::string line = head.substr(pos, eol - pos);
        pos = eol + 1;
        // MetaIO reads keys as C strings and ends a key at '=' or ':' (MET_Read): a NUL cuts
        // a key short ("NDims\0..." is NDims to MetaIO), and "NDims: 40000" sets NDims. Both
        // slipped past this check, and a TransformMatrix then made MetaIO read NDims^2
        // numbers (fuzz_metaimage: a 530-byte header hung the Release CLI for more than 20 s;
        // "NDims: 40000" took 8.5 s). So NUL is refused, and ':' separates as '=' does.
        if (line.find('\0') != std::string::npos)
            throw Error(path, "header",
                        "line " + std::to_string(n) +
                            " holds a NUL byte (expected a text header before ElementDataFile)");
        const size_t eq = line.find_first_of("=:");
        const std::string key = trim(line.substr(0, eq));
        const std::string value = eq == std::string::npos ? "" : trim(line.substr(eq + 1));
        if (key.size() > kMaxField || value.size() > kMaxField)
            throw Error(path, "header",
                        "line " + std::to_string(n) + " has a " +
                            (key.size() > kMaxField ? "key" : "value") + " of " +
                            std::to_string(std::max(key.size(), value.size())) +
                            " characters, MetaImage allows " + std::to_string(kMaxField));
        // A line without a separator is no field, but MetaIO's key runs on across the newline
        // to the next '=' ("NDims\nTransformMatrix = -1 ..." set NDims to -1 unseen, and MetaIO
        // then read NDims^2 numbers: a hang, fuzz_metaimage, 2026-12-07). So every non-blank
        // line is "Key = value" (or "Key: value"), and what MetaIO reads is what was checked.
        if (eq == std::string::npos) {
            if (key.empty()) continue;
            throw Error(path, "header",
                        "line " + std::to_string(n) + " '" + one_line(key, 40) +
                            "' has no '=' (expected 'Key = value' lines up to ElementDataFile)");
        }
        // The header ends where MetaIO's ends: at the key ElementDataFile, spelt exactly so
        // (MET_Read compares keys with strcmp). Stopping at any spelling let MetaIO parse on,
        // unchecked, past an "elementDataFile" line into the voxels, where a key longer than its
        // char[255] aborted in strcpy (fuzz_metaimage, 2026-12-02).
        if (key == "ElementDataFile") return orientation;
        if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation")
            orientation.has_matrix = true;
        // A geometry number that is not finite ("nan", "inf", 1e999) made MetaIO stop reading
        // the header and blame a later field ("DimSize required and not defined"): name the
        // field it is in (issue 14, bad input). Tokens strtod cannot read are MetaIO's to judge.
        if (geometry_key(key))
            for (const std::string& t : split_words(value)) {
                char* end = nullptr;
                const double x = std::strtod(t.c_str(), &end);
                if (end && *end == '\0' && !std::isfinite(x))
                    throw Error(path, key,
                                "expected finite numbers, got '" + one_line(value, 80) + "'");
            }
        if (key == "AnatomicalOrientation") orientation.anatomical_orientation = value;
        if (to_lower(key) != "ndims") continue;
        if (value != "3" && value != "4")
            throw Error(path, "header",
                        "expected NDims = 3 (or 4 with a last size of 1), got '" +
                            one_line(value, 40) + "'");
    }
    throw Error(path, "header", "no ElementDataFile line in the first MiB of the header");
}

namespace {

// The MetaIO code of an LPS direction: for each index axis (column), the letter of the side it
// comes from along its largest component (+x LPS runs from R to L: 'R').
std::string metaio_code(const double* direction) {
    const char from[3][2] = {{'R', 'L'}, {'A', 'P'}, {'I', 'S'}};  // [LPS axis][+, -]
    std::string code;
    for (int c = 0; c < 3; ++c) {
        int best = 0;
        for (int r = 1; r < 3; ++r)
            if (std::abs(direction[r * 3 + c]) > std::abs(direction[best * 3 + c])) best = r;
        code += from[best][direction[best * 3 + c] < 0];
    }
    return code;
}

}  // namespace

void apply_anatomical_orientation(const MetaHeaderOrientation& h, Volume& v,
                                  const std::string& path) {
    const std::string& ao = h.anatomical_orientation;
    if (ao.empty() || ao.find_first_not_of('?') == std::string::npos) return;
    // For each letter: the LPS axis and the sign of the direction the index axis points in.
    auto axis_of = [](char c, int& axis, double& sign) {
        const char* letters = "RLAPIS";  // from R: +x (toward L); from L: -x; from A: +y; ...
        const char* p = std::strchr(letters, c);
        if (c == '\0' || !p) return false;
        axis = int(p - letters) / 2;
        sign = (p - letters) % 2 ? -1.0 : 1.0;
        return true;
    };
    double d[9] = {};
    bool used[3] = {false, false, false};
    bool ok = ao.size() >= 3 && ao.find_first_of(" \t") == std::string::npos;
    for (int c = 0; ok && c < 3; ++c) {
        int axis = 0;
        double sign = 1;
        ok = axis_of(ao[size_t(c)], axis, sign) && !used[axis];
        if (ok) used[axis] = true, d[axis * 3 + c] = sign;
    }
    // A 4D file (last size 1) may name a fourth axis: anything after the third letter is ignored.
    if (!ok)
        throw Error(path, "AnatomicalOrientation",
                    "expected three letters, one of R/L, A/P and S/I each, naming the side each "
                    "axis comes from (RAI: x from right to left, y from anterior to posterior, z "
                    "from inferior to superior), got '" +
                        one_line(ao, 40) + "'");
    const std::string code = ao.substr(0, 3);
    if (!h.has_matrix) {
        for (int i = 0; i < 9; ++i) v.direction[i] = d[i];
        v.geometry_source = "MetaImage AnatomicalOrientation " + code +
                            " (no TransformMatrix; MetaIO letters: the side each axis comes "
                            "from) and Offset, LPS";
        return;
    }
    const std::string from_matrix = metaio_code(v.direction);
    if (from_matrix != code)
        v.geometry_source += "; AnatomicalOrientation " + code +
                             " disagrees with TransformMatrix (" + from_matrix +
                             " in MetaIO letters): TransformMatrix wins, as in ITK";
}

std::optional<MetaDataLayout> metaimage_layout(const std::string& header_path,
                                               const std::string& data_file, int header_size,
                                               bool compressed, bool binary, bool msb,
                                               size_t data_bytes, bool allow_external) {
    const bool local = data_file == "LOCAL";
    if (!local) {
        if (data_file.empty() || data_file.rfind("LIST", 0) == 0 ||
            data_file.find('%') != std::string::npos || data_file.find(' ') != std::string::npos)
            throw Error(header_path, "ElementDataFile",
                        "expected LOCAL or one data file name, got '" + one_line(data_file, 120) +
                            "' (slice lists and name patterns are not supported)");
        check_data_file(header_path, "ElementDataFile", data_file, allow_external);
    }
    if (!binary) return std::nullopt;  // ASCII voxels: MetaIO parses them
    MetaDataLayout l;
    l.compressed = compressed;
    l.swap = msb != host_is_big_endian();
    if (local) {
        l.path = header_path;
        l.offset = local_data_offset(header_path);
        if (l.offset < 0) return std::nullopt;
    } else {
        const fs::path p(data_file);
        l.path = p.is_absolute() ? p.string() : (fs::path(header_path).parent_path() / p).string();
        l.offset = 0;
    }
    std::error_code ec;
    const uint64_t size = fs::file_size(l.path, ec);
    if (ec)
        throw Error(header_path, "voxel data",
                    "cannot open the data file " + fs::path(l.path).filename().string() + ": " +
                        ec.message());
    if (header_size > 0) l.offset += header_size;
    if (header_size == -1 && !compressed) l.offset = int64_t(size) - int64_t(data_bytes);
    if (!compressed && (l.offset < 0 || size < sat_add(uint64_t(l.offset), data_bytes)))
        throw Error(header_path, "voxel data",
                    "truncated: expected " + std::to_string(data_bytes) +
                        " bytes of voxels, the data file has " +
                        std::to_string(l.offset < 0 || size < uint64_t(l.offset)
                                           ? 0
                                           : size - uint64_t(l.offset)));
    return l;
}

void read_metaimage_voxels(const MetaDataLayout& l, DiskType disk, Volume& v,
                           const std::string& where, const std::function<void(double)>& progress) {
    std::ifstream in(l.path, std::ios::binary);
    if (!in)
        throw Error(
            where, "voxel data",
            "cannot open " + fs::path(l.path).filename().string() + ": " + std::strerror(errno));
    in.seekg(l.offset);
    if (l.compressed) {
        Inflater inflater(in, where);
        read_voxel_stream([&](void* buf, size_t n) { return inflater.read(buf, n); }, disk, l.swap,
                          v, where, progress);
    } else {
        read_voxel_stream(
            [&](void* buf, size_t n) {
                in.read(static_cast<char*>(buf), std::streamsize(n));
                if (in.bad()) throw Error(where, "voxel data", "read error");
                return size_t(in.gcount());
            },
            disk, l.swap, v, where, progress);
    }
}

}  // namespace lacuna::io
