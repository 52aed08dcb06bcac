#include "io/nrrd_data.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/io_util.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace fs = std::filesystem;

namespace {

// Every "key: value" field of a NRRD header, in order, to visit(key, value) (both trimmed; comment
// lines and lines without a colon skipped; at most 10000 lines): the one walk of the three
// readers below. It stops at the blank line that ends an attached header; `end`, if given,
// receives whether that line came and the offset of the first byte after it.
struct HeaderEnd {
    bool blank_line = false;
    uint64_t offset = 0;
};
template <class Visit>
void for_each_nrrd_field(const std::string& header, Visit&& visit, HeaderEnd* end = nullptr) {
    std::ifstream in(header, std::ios::binary);
    std::string line;
    HeaderEnd e;
    for (int n = 0; n < 10000 && std::getline(in, line); ++n) {
        e.offset += line.size() + 1;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) {
            e.blank_line = true;
            break;
        }
        const size_t colon = line.find(':');
        if (line[0] == '#' || colon == std::string::npos) continue;
        visit(trim(line.substr(0, colon)), trim(line.substr(colon + 1)));
    }
    if (end) *end = e;
}

// The header's fields that place the data, and where the header ends in its own file.
struct NrrdFields {
    std::string encoding = "raw", data_file;
    long long byte_skip = 0, line_skip = 0;
    uint64_t header_end = 0;  // first byte after the blank line
    bool has_blank_line = false;
};

NrrdFields parse_fields(const std::string& header) {
    NrrdFields f;
    HeaderEnd end;
    for_each_nrrd_field(
        header,
        [&](const std::string& key, const std::string& value) {
            if (key == "encoding")
                f.encoding = to_lower(value);
            else if (key == "data file" || key == "datafile")
                f.data_file = value;
            else if (key == "byte skip" || key == "byteskip")
                f.byte_skip = std::atoll(value.c_str());
            else if (key == "line skip" || key == "lineskip")
                f.line_skip = std::atoll(value.c_str());
        },
        &end);
    f.header_end = end.offset;
    f.has_blank_line = end.blank_line;
    return f;
}

// Skips `lines` newline-terminated lines from `offset`; -1 if the file ends first.
int64_t skip_lines(const std::string& path, uint64_t offset, long long lines) {
    if (lines <= 0) return int64_t(offset);
    std::ifstream in(path, std::ios::binary);
    in.seekg(std::streamoff(offset));
    std::vector<char> buf(size_t(1) << 16);
    int64_t at = int64_t(offset);
    while (lines > 0 && in) {
        in.read(buf.data(), std::streamsize(buf.size()));
        const std::streamsize got = in.gcount();
        for (std::streamsize i = 0; i < got; ++i)
            if (buf[size_t(i)] == '\n' && --lines == 0) return at + i + 1;
        at += got;
        if (got == 0) break;
    }
    return -1;
}

Error truncated(const std::string& header, uint64_t need, uint64_t have, const std::string& what) {
    return Error(header, "voxel data",
                 "truncated: expected " + std::to_string(need) + " bytes of " + what +
                     ", the data file has " + std::to_string(have));
}

// The "(a,b,c)" vectors of a space directions / space origin value ("none" entries as empty
// vectors); false when the value is not a list of such vectors.
bool nrrd_vectors(const std::string& value, std::vector<std::vector<double>>& out,
                  bool& all_finite) {
    all_finite = true;
    size_t at = 0;
    while ((at = value.find_first_not_of(" \t", at)) != std::string::npos) {
        if (value.compare(at, 4, "none") == 0) {
            out.emplace_back();
            at += 4;
            continue;
        }
        if (value[at] != '(') return false;
        const size_t close = value.find(')', at);
        if (close == std::string::npos) return false;
        std::vector<double> v;
        std::stringstream parts(value.substr(at + 1, close - at - 1));
        for (std::string t; std::getline(parts, t, ',');) {
            t = trim(t);
            char* end = nullptr;
            const double x = std::strtod(t.c_str(), &end);
            if (t.empty() || !end || *end != '\0') return false;
            all_finite = all_finite && std::isfinite(x);
            v.push_back(x);
        }
        out.push_back(std::move(v));
        at = close + 1;
    }
    return true;
}

}  // namespace

void check_nrrd_geometry(const std::string& header) {
    for_each_nrrd_field(header, [&](const std::string& key, const std::string& value) {
        if (key != "space directions" && key != "space origin") return;
        std::vector<std::vector<double>> vectors;
        bool finite = true;
        if (!nrrd_vectors(value, vectors, finite)) return;  // NrrdIO's to judge
        if (!finite)
            throw Error(header, key,
                        "expected finite coordinates, got '" + one_line(value, 120) + "'");
        if (key != "space directions") return;
        for (size_t a = 0; a < vectors.size(); ++a) {
            const std::vector<double>& v = vectors[a];
            if (!v.empty() && std::all_of(v.begin(), v.end(), [](double x) { return x == 0; }))
                throw Error(header, key,
                            "axis " + std::to_string(a) +
                                " is the zero vector (a zero or singular affine): '" +
                                one_line(value, 120) + "'");
        }
    });
}

bool apply_nrrd_las_space(const std::string& header, Volume& v) {
    std::string space;
    std::vector<std::vector<double>> dirs, origin;
    bool finite = true, parsed = true;
    for_each_nrrd_field(header, [&](const std::string& key, const std::string& value) {
        if (key == "space") space = to_lower(value);
        if (key == "space directions" && parsed) parsed = nrrd_vectors(value, dirs, finite);
        if (key == "space origin" && parsed) parsed = nrrd_vectors(value, origin, finite);
    });
    if (!parsed) return false;
    if (space != "left-anterior-superior" && space != "las" &&
        space != "left-anterior-superior-time" && space != "last")
        return false;
    std::vector<std::vector<double>> domain;
    for (const auto& d : dirs)
        if (!d.empty()) domain.push_back(d);
    if (!finite || domain.size() != 3) return false;
    for (int a = 0; a < 3; ++a) {
        const std::vector<double>& d = domain[size_t(a)];
        if (d.size() < 3) return false;
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0)) return false;  // check_nrrd_geometry refused it already
        const double lps[3] = {d[0], -d[1], d[2]};
        for (int r = 0; r < 3; ++r) v.direction[r * 3 + a] = lps[r] / len + 0.0;
    }
    if (origin.size() == 1 && origin[0].size() >= 3)
        v.origin = {origin[0][0], -origin[0][1] + 0.0, origin[0][2]};
    return true;
}

std::optional<MetaDataLayout> nrrd_layout(const std::string& header,
                                          const std::vector<std::string>& data_files,
                                          uint64_t data_bytes, uint64_t voxels, bool swap) {
    const NrrdFields f = parse_fields(header);
    const bool raw = f.encoding == "raw";
    const bool gzip = f.encoding == "gzip" || f.encoding == "gz";
    const bool ascii = f.encoding == "ascii" || f.encoding == "txt" || f.encoding == "text";
    const bool hex = f.encoding == "hex";
    // What the data must at least hold in the file: raw its bytes, hex two characters a byte,
    // ascii one character a value; compressed data has no lower bound worth checking.
    const uint64_t at_least = raw ? data_bytes : hex ? sat_mul(data_bytes, 2) : ascii ? voxels : 0;
    const std::string what = raw ? "voxels" : hex ? "hex digits" : "ascii values";

    std::error_code ec;
    const fs::path dir = fs::path(header).parent_path();
    const bool one_file = !f.data_file.empty() && f.data_file.rfind("LIST", 0) != 0 &&
                          f.data_file.find('%') == std::string::npos;
    // LIST or pattern (the names were checked by check_nrrd_data_files): read by NrrdIO,
    // after checking that the files together hold the raw bytes (skips make them need more).
    if (!f.data_file.empty() && !one_file) {
        uint64_t total = 0;
        for (const auto& file : data_files) {
            const uint64_t n = fs::file_size(file, ec);
            if (!ec) total = sat_add(total, n);
        }
        if (raw && total < data_bytes) throw truncated(header, data_bytes, total, what);
        return std::nullopt;
    }
    MetaDataLayout l;
    l.swap = swap;
    l.compressed = gzip;
    if (one_file) {
        const fs::path p(f.data_file);
        l.path = (p.is_absolute() ? p : dir / p).string();
        l.offset = 0;
    } else {
        if (!f.has_blank_line)
            throw Error(header, "header", "the header never ends (no blank line before the data)");
        l.path = header;
        l.offset = int64_t(f.header_end);
    }
    const uint64_t size = fs::file_size(l.path, ec);
    if (ec) throw Error(header, "voxel data", "cannot read the data file: " + ec.message());
    const int64_t after_lines = skip_lines(l.path, uint64_t(l.offset), f.line_skip);
    if (after_lines < 0) throw truncated(header, at_least, 0, what);
    l.offset = after_lines;
    if (f.byte_skip == -1) {
        // "-1: the data is at the end of the file" (raw only).
        if (!raw) return std::nullopt;
        if (size < data_bytes) throw truncated(header, data_bytes, size, what);
        l.offset = int64_t(size - data_bytes);
    } else if (f.byte_skip < 0) {
        throw Error(header, "byte skip",
                    "expected -1 or a byte count >= 0, got " + std::to_string(f.byte_skip));
    } else if (raw) {
        l.offset = int64_t(sat_add(uint64_t(l.offset), uint64_t(f.byte_skip)));
    }
    const uint64_t have = size > uint64_t(l.offset) ? size - uint64_t(l.offset) : 0;
    if (have < at_least) throw truncated(header, at_least, have, what);
    // gzip with a byte skip skips inflated bytes: rare, left to NrrdIO.
    if (raw || (gzip && f.byte_skip == 0)) return l;
    return std::nullopt;
}

}  // namespace lacuna::io
