#include "dist/brick_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "lacuna/error.h"

namespace lacuna::dist {

Volume crop_brick(const Volume& whole, Vec3i offset, Vec3i dims) {
    const Vec3i wd = whole.dims();
    for (int a = 0; a < 3; ++a)
        if (offset[a] < 0 || dims[a] < 2 || offset[a] + dims[a] > wd[a])
            throw Error("brick", "voxels", "expected a brick inside the volume");
    Volume b(dims, whole.type(), "brick");
    const size_t vs = voxel_size(whole.type());
    const auto* src = static_cast<const uint8_t*>(whole.data());
    auto* dst = static_cast<uint8_t*>(b.data());
    const size_t row = size_t(dims.x) * vs;
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            std::memcpy(dst + b.index(0, j, k) * vs,
                        src + whole.index(offset.x, offset.y + j, offset.z + k) * vs, row);
    b.spacing = whole.spacing;
    b.origin = whole.origin;
    std::copy_n(whole.direction, 9, b.direction);
    b.geometry_source = whole.geometry_source;
    b.compute_range("brick");
    b.set_vis_range(whole.vis_range());
    return b;
}

}  // namespace lacuna::dist

namespace lacuna::dist {

namespace {
bool host_little_endian() {
    const uint16_t one = 1;
    uint8_t b;
    std::memcpy(&b, &one, 1);
    return b == 1;
}
}  // namespace

std::optional<RawBrickFile> raw_brick_file(const std::string& path,
                                           const std::optional<RawSpec>& raw) {
    const std::filesystem::path p(path);
    std::string ext = p.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".raw") return std::nullopt;
    const std::optional<RawSpec> spec = raw ? raw : raw_spec_from_name(path);
    if (!spec || spec->type == VoxelType::Float32 || spec->big_endian == host_little_endian())
        return std::nullopt;
    // The checks read_volume makes, before any rank reads a byte: a layout it would refuse is
    // refused alike.
    for (int a = 0; a < 3; ++a)
        if (spec->dims[a] < 2 || spec->dims[a] > kMaxDim || !(spec->spacing[a] > 0) ||
            !std::isfinite(spec->spacing[a]))
            return std::nullopt;  // read_volume names the problem
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(p, ec);
    const uint64_t want = uint64_t(spec->dims.x) * uint64_t(spec->dims.y) * uint64_t(spec->dims.z) *
                          voxel_size(spec->type);
    if (ec || size != want) return std::nullopt;  // read_volume names it
    return RawBrickFile{path, *spec};
}

Volume header_of(const RawBrickFile& f) {
    Volume v(f.spec.dims, f.spec.type, nullptr, nullptr);
    v.spacing = f.spec.spacing;
    return v;
}

Volume read_brick(const RawBrickFile& f, Vec3i offset, Vec3i dims) {
    const Vec3i wd = f.spec.dims;
    for (int a = 0; a < 3; ++a)
        if (offset[a] < 0 || dims[a] < 2 || offset[a] + dims[a] > wd[a])
            throw Error("brick", "voxels", "expected a brick inside the volume");
    std::ifstream in(f.path, std::ios::binary);
    if (!in) throw Error(f.path, "file", std::string("cannot open: ") + std::strerror(errno));
    Volume b(dims, f.spec.type, f.path);
    b.spacing = f.spec.spacing;
    const size_t vs = voxel_size(f.spec.type);
    auto* dst = static_cast<char*>(b.data());
    const std::streamsize row = std::streamsize(size_t(dims.x) * vs);
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j) {
            // One row of the brick: voxels offset.x .. offset.x + dims.x - 1 of file row (y, z).
            const uint64_t at =
                ((uint64_t(offset.z + k) * uint64_t(wd.y) + uint64_t(offset.y + j)) *
                     uint64_t(wd.x) +
                 uint64_t(offset.x)) *
                vs;
            in.seekg(std::streamoff(at));
            in.read(dst + b.index(0, j, k) * vs, row);
            if (in.gcount() != row) throw Error(f.path, "voxel data", "read error or truncated");
        }
    b.compute_range(f.path);
    return b;
}

ValueRange default_vis_range(float lo, float hi) {
    Volume v({2, 2, 2}, VoxelType::Float32, "range");
    for (int i = 0; i < 8; ++i) v.data_as<float>()[i] = i == 0 ? hi : lo;
    v.compute_range("range");
    return v.vis_range();
}

}  // namespace lacuna::dist
