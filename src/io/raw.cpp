// Headerless ("raw") volumes: voxels only, x fastest, layout from ReadOptions::raw or the name.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>

#include "io/io_util.h"
#include "io/readers.h"
#include "lacuna/error.h"
#include "lacuna/io.h"

namespace lacuna {

std::optional<RawSpec> raw_spec_from_name(const std::string& path) {
    const std::string name = std::filesystem::path(path).filename().string();
    // "<anything>_<X>x<Y>x<Z>_<type>[_le|_be].raw", the dims may also start the name.
    static const std::regex pattern(
        R"((?:^|_)(\d+)x(\d+)x(\d+)_(uint8|int16|uint16|float32|float)(?:_(le|be))?\.raw$)",
        std::regex::icase | std::regex::ECMAScript);
    std::smatch m;
    if (!std::regex_search(name, m, pattern)) return std::nullopt;
    RawSpec spec;
    for (int a = 0; a < 3; ++a) {
        const std::string digits = m[a + 1].str();
        long long d = 0;
        const auto res = std::from_chars(digits.data(), digits.data() + digits.size(), d);
        // Out-of-range sizes saturate so validation reports them instead of wrapping.
        if (res.ec != std::errc() || d > std::numeric_limits<int>::max())
            d = std::numeric_limits<int>::max();
        spec.dims[a] = int(d);
    }
    spec.type = parse_voxel_type(io::to_lower(m[4].str()), path);
    spec.big_endian = io::to_lower(m[5].str()) == "be";
    return spec;
}

namespace io {

Volume read_raw(const std::string& path, const ReadOptions& opts, VoxelLayout* header_only) {
    std::optional<RawSpec> spec = opts.raw ? opts.raw : raw_spec_from_name(path);
    if (!spec)
        throw Error(path, "raw layout",
                    "unknown dims and type: name the file like head_301x370x316_uint8.raw or "
                    "pass the layout explicitly");
    for (int a = 0; a < 3; ++a) {
        if (spec->dims[a] < 2 || spec->dims[a] > kMaxDim)
            throw Error(path, "dims",
                        "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                            std::to_string(spec->dims.x) + "x" + std::to_string(spec->dims.y) +
                            "x" + std::to_string(spec->dims.z));
        if (!(spec->spacing[a] > 0) || !std::isfinite(spec->spacing[a]))
            throw Error(path, "spacing",
                        "expected positive spacing, got " + to_string(spec->spacing));
    }
    // The size and budget checks come before the allocation, so a wrong name costs nothing.
    const uint64_t expected = grid_bytes(spec->dims, voxel_size(spec->type));
    if (!header_only)
        check_budget(path, "dims", dims_string(spec->dims) + " " + to_string(spec->type), expected,
                     opts.max_memory);
    std::error_code ec;
    const uint64_t actual = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path, "file", "cannot read its size: " + ec.message());
    if (actual != expected)
        throw Error(path, "file size",
                    "a " + std::to_string(spec->dims.x) + "x" + std::to_string(spec->dims.y) + "x" +
                        std::to_string(spec->dims.z) + " " + to_string(spec->type) +
                        " volume needs " + std::to_string(expected) + " bytes, the file has " +
                        std::to_string(actual));
    if (header_only) {
        *header_only = {path, 0, disk_type_of(spec->type), spec->big_endian != host_is_big_endian(),
                        true};
        Volume h(spec->dims, spec->type, nullptr, nullptr);
        h.spacing = spec->spacing;
        return h;
    }

    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "file", std::string("cannot open: ") + std::strerror(errno));
    Volume v(spec->dims, spec->type, path);
    v.spacing = spec->spacing;
    read_voxel_stream(
        [&](void* buf, size_t n) {
            in.read(static_cast<char*>(buf), std::streamsize(n));
            if (in.bad()) throw Error(path, "voxel data", "read error");
            return size_t(in.gcount());
        },
        disk_type_of(spec->type), spec->big_endian != host_is_big_endian(), v, path, opts.progress);
    return v;
}

void write_raw(const std::string& path, const Volume& v) {
    check_writable_dir(path);
    const TempName tmp = temp_name_beside(path);
    remove_stale_temp_files(tmp.dir);
    try {
        {
            std::ofstream out(tmp.path, std::ios::binary | std::ios::trunc);
            if (!out)
                throw Error(path, "output", std::string("cannot write: ") + std::strerror(errno));
            // Raw files are little-endian by convention (see docs/formats.md).
            if (host_is_big_endian() && voxel_size(v.type()) > 1)
                throw Error(path, "output", "raw output on big-endian hosts is not supported");
            out.write(static_cast<const char*>(v.data()), std::streamsize(v.bytes()));
            out.flush();
            if (!out)
                throw Error(path, "output", std::string("cannot write: ") + std::strerror(errno));
        }
        expect_file_size(tmp.path, v.bytes(), path);
        sync_file(tmp.path, path);
        rename_over(tmp.path, path);
        sync_dir(tmp.dir);
    } catch (...) {
        remove_temp_files(tmp);
        throw;
    }
}

}  // namespace io
}  // namespace lacuna
