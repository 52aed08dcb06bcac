#include "io/brick_read.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <new>

#include "io/io_util.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"

namespace lacuna::io {

std::optional<BrickFile> open_brick_file(const std::string& path, const ReadOptions& opts) {
    try {
        std::error_code ec;
        if (path.empty() || std::filesystem::is_directory(path, ec)) return std::nullopt;  // DICOM
        const std::string ext = format_extension(path);
        const bool nifti =
            ext == ".nii" || ext == ".nii.gz" || ext == ".hdr" || ext == ".img" || ext == ".img.gz";
        if (opts.frame && *opts.frame != 0 && !nifti) return std::nullopt;  // read_volume says it
        check_readable_file(path);
        // read_volume's dispatch, each reader asked for the header alone.
        VoxelLayout layout;
        Volume header = nifti           ? read_nifti(path, opts, RgbOpacity::Luminance, &layout)
                        : ext == ".raw" ? read_raw(path, opts, &layout)
                                        : read_itk(path, opts, &layout);
        if (!layout.at_offset) return std::nullopt;
        check_geometry(header, path);
        return BrickFile{path, std::move(header), std::move(layout)};
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw Error(path, "memory", "out of memory while reading the header");
    } catch (const std::exception& e) {
        throw Error(path, "read", one_line(e.what()));
    }
}

Volume read_brick(const BrickFile& f, Vec3i offset, Vec3i dims, const MemoryBudget& budget) {
    const Vec3i wd = f.header.dims();
    for (int a = 0; a < 3; ++a)
        if (offset[a] < 0 || dims[a] < 2 || offset[a] + dims[a] > wd[a])
            throw Error(f.path, "brick", "expected a brick inside the volume");
    check_budget(f.path, "dims",
                 "a brick of " + dims_string(dims) + " " + to_string(f.header.type()),
                 grid_bytes(dims, voxel_size(f.header.type())), budget);
    const VoxelLayout& l = f.layout;
    const int fd = ::open(l.path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(l.path, "file", std::string("cannot open: ") + std::strerror(errno));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};

    Volume b(dims, f.header.type(), f.path);
    b.spacing = f.header.spacing;
    b.origin = f.header.origin;
    std::copy_n(f.header.direction, 9, b.direction);
    b.geometry_source = f.header.geometry_source;

    // The brick as one stream of its rows in the volume's order (k, then j): byte `at` of the
    // stream is byte at % row of row at / row, which starts in the file at the voxel
    // (offset.x, offset.y + j, offset.z + k). A brick spanning x reads runs of whole rows (and
    // planes) in one pread. read_voxel_stream then swaps and converts as read_volume does.
    const uint64_t elem = disk_type_size(l.disk);
    const uint64_t row = uint64_t(dims.x) * elem;
    const bool full_x = offset.x == 0 && dims.x == wd.x;
    uint64_t at = 0;  // bytes of the stream served so far
    auto read = [&](void* buf, size_t n) -> size_t {
        auto* out = static_cast<char*>(buf);
        size_t done = 0;
        while (done < n) {
            const uint64_t r = at / row, in_row = at % row;
            const uint64_t j = r % uint64_t(dims.y), k = r / uint64_t(dims.y);
            if (k >= uint64_t(dims.z)) break;  // the brick's end
            const uint64_t voxel =
                ((uint64_t(offset.z) + k) * uint64_t(wd.y) + uint64_t(offset.y) + j) *
                    uint64_t(wd.x) +
                uint64_t(offset.x);
            // Contiguous in the file: the rest of this row, or (spanning x) of this plane's rows.
            uint64_t run = row - in_row;
            if (full_x) run += (uint64_t(dims.y) - 1 - j) * row;
            const size_t want = size_t(std::min<uint64_t>(run, n - done));
            const ssize_t got =
                ::pread(fd, out + done, want, off_t(l.offset + voxel * elem + in_row));
            if (got < 0 && errno == EINTR) continue;
            if (got <= 0)
                throw Error(l.path, "voxel data",
                            got < 0 ? std::string("read error: ") + std::strerror(errno)
                                    : std::string("truncated: the file ends inside the brick"));
            done += size_t(got);
            at += uint64_t(got);
        }
        return done;
    };
    read_voxel_stream(read, l.disk, l.swap, b, f.path, {}, l.rescale, l.slope, l.intercept);
    return b;
}

}  // namespace lacuna::io
