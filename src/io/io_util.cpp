#include "io/io_util.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <vector>

#include "lacuna/error.h"

namespace lacuna {

namespace {

uint64_t physical_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return uint64_t(1) << 34;  // unknown: assume 16 GiB
    return uint64_t(pages) * uint64_t(page);
}

// cgroup v2 limit of this process ("max" or absent: no limit).
uint64_t cgroup_memory_limit() {
    std::ifstream in("/sys/fs/cgroup/memory.max");
    uint64_t v = 0;
    if (in >> v && v > 0) return v;
    return UINT64_MAX;
}

}  // namespace

uint64_t default_memory_budget() {
    return std::min(physical_memory(), cgroup_memory_limit()) / 2;
}

std::string format_bytes(uint64_t bytes) {
    static const char* kUnits[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1000.0 && u < 6) {
        v /= 1000.0;
        ++u;
    }
    char buf[32];
    if (u == 0 || v >= 10.0)
        std::snprintf(buf, sizeof buf, "%.0f %s", v, kUnits[u]);
    else
        std::snprintf(buf, sizeof buf, "%.1f %s", v, kUnits[u]);
    return buf;
}

}  // namespace lacuna

namespace lacuna::io {

std::string trim(const std::string& s) {
    const size_t b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

namespace fs = std::filesystem;

uint64_t grid_bytes(Vec3i d, uint64_t elem) {
    const auto dim = [](int x) { return uint64_t(std::max(x, 0)); };
    return sat_mul(sat_mul(sat_mul(dim(d.x), dim(d.y)), dim(d.z)), elem);
}

std::string dims_string(Vec3i d) {
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

void check_budget(const std::string& where, const std::string& field, const std::string& what,
                  uint64_t need, const MemoryBudget& budget) {
    const uint64_t limit = budget.bytes ? budget.bytes : default_memory_budget();
    if (need <= limit) return;
    throw Error(where, field,
                what + " needs " +
                    (need == UINT64_MAX ? std::string("more than 18 EB") : format_bytes(need)) +
                    ", more than " + budget.name + " " + format_bytes(limit));
}

std::string to_lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string format_extension(const std::string& path) {
    const std::string name = to_lower(fs::path(path).filename().string());
    for (const char* two : {".nii.gz", ".img.gz", ".raw.gz"}) {
        const size_t n = std::strlen(two);
        if (name.size() > n && name.compare(name.size() - n, n, two) == 0) return two;
    }
    const size_t dot = name.rfind('.');
    if (dot == std::string::npos || dot == 0) return "";
    return name.substr(dot);
}

void check_readable_file(const std::string& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) {
        if (ec && ec != std::errc::no_such_file_or_directory)
            throw Error(path, "file", "cannot access: " + ec.message());
        throw Error(path, "file", "does not exist");
    }
    if (fs::is_directory(st)) throw Error(path, "file", "is a directory, expected a file");
    if (!fs::is_regular_file(st)) throw Error(path, "file", "is not a regular file");
    if (::access(path.c_str(), R_OK) != 0)
        throw Error(path, "file", std::string("cannot read: ") + std::strerror(errno));
}

void check_writable_dir(const std::string& path) {
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    const fs::file_status st = fs::status(dir, ec);
    int err = 0;
    if (!fs::exists(st))
        err = ENOENT;
    else if (!fs::is_directory(st))
        err = ENOTDIR;
    else if (::access(dir.c_str(), W_OK | X_OK) != 0)
        err = errno;
    if (err) throw Error(path, "output", std::string("cannot write: ") + std::strerror(err));
}

std::string one_line(const std::string& text, size_t max_chars) {
    std::string out;
    out.reserve(std::min(text.size(), max_chars + 3));
    bool space = false;
    for (char c : text) {
        if (c == '\n' || c == '\r' || c == '\t' || c == ' ') {
            space = !out.empty();
            continue;
        }
        if (static_cast<unsigned char>(c) < 0x20) continue;
        if (space) out += ' ';
        space = false;
        out += c;
        if (out.size() >= max_chars) {
            out += "...";
            break;
        }
    }
    return out.empty() ? std::string("unknown error") : out;
}

TempName temp_name_beside(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    const fs::path p(path);
    TempName t;
    t.dir = p.parent_path().empty() ? std::string(".") : p.parent_path().string();
    t.prefix = ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-";
    t.path = (fs::path(t.dir) / (t.prefix + p.filename().string())).string();
    return t;
}

void remove_temp_files(const TempName& t) noexcept {
    std::error_code ec;
    std::vector<fs::path> doomed;
    for (fs::directory_iterator it(t.dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, t.prefix.size(), t.prefix) == 0) doomed.push_back(it->path());
    }
    for (const auto& p : doomed) fs::remove_all(p, ec);  // a DICOM output folder, too
}

void remove_stale_temp_files(const std::string& dir) noexcept {
    std::error_code ec;
    const long self = long(::getpid());
    std::vector<fs::path> doomed;
    for (fs::directory_iterator it(dir.empty() ? "." : dir, ec), end; !ec && it != end;
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        long pid = 0;
        unsigned n = 0;
        int used = 0;
        if (std::sscanf(name.c_str(), ".tmp-%ld-%u-%n", &pid, &n, &used) != 2 || used == 0)
            continue;
        if (pid <= 0 || pid == self) continue;
        if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours)
        doomed.push_back(it->path());
    }
    for (const auto& p : doomed) fs::remove_all(p, ec);
}

void sync_file(const std::string& path, const std::string& where) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    int err = fd < 0 ? errno : 0;
    if (fd >= 0) {
        if (::fsync(fd) != 0) err = errno;
        if (::close(fd) != 0 && !err) err = errno;
    }
    if (err)
        throw Error(where, "output", std::string("cannot write: fsync: ") + std::strerror(err));
}

void sync_dir(const std::string& dir) noexcept {
    const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

void expect_file_size(const std::string& path, uint64_t expected, const std::string& where,
                      bool at_least) {
    std::error_code ec;
    const uint64_t got = fs::file_size(path, ec);
    if (ec) throw Error(where, "output", "cannot write: " + ec.message());
    if (got == expected || (at_least && got > expected)) return;
    throw Error(where, "output",
                "cannot write: the file has " + std::to_string(got) + " bytes, expected " +
                    (at_least ? "at least " : "") + std::to_string(expected) +
                    " (disk full or file size limit?)");
}

void rename_over(const std::string& from, const std::string& to) {
    if (std::rename(from.c_str(), to.c_str()) != 0)
        throw Error(to, "output",
                    std::string("cannot write: rename failed: ") + std::strerror(errno));
}

void write_text_atomic(const std::string& path, const std::string& text) {
    const TempName tmp = temp_name_beside(path);
    remove_stale_temp_files(tmp.dir);
    try {
        {
            std::ofstream f(tmp.path, std::ios::binary);
            f << text;
            f.flush();
            if (!f) throw Error(path, "output", "cannot write the file");
        }
        expect_file_size(tmp.path, text.size(), path);
        sync_file(tmp.path, path);
        rename_over(tmp.path, path);
        sync_dir(tmp.dir);
    } catch (...) {
        remove_temp_files(tmp);
        throw;
    }
}

size_t disk_type_size(DiskType t) {
    switch (t) {
        case DiskType::U8:
        case DiskType::I8:
            return 1;
        case DiskType::U16:
        case DiskType::I16:
            return 2;
        case DiskType::U32:
        case DiskType::I32:
        case DiskType::F32:
            return 4;
        case DiskType::U64:
        case DiskType::I64:
        case DiskType::F64:
            return 8;
    }
    return 1;
}

std::string to_string(DiskType t) {
    switch (t) {
        case DiskType::U8:
            return "uint8";
        case DiskType::I8:
            return "int8";
        case DiskType::U16:
            return "uint16";
        case DiskType::I16:
            return "int16";
        case DiskType::U32:
            return "uint32";
        case DiskType::I32:
            return "int32";
        case DiskType::U64:
            return "uint64";
        case DiskType::I64:
            return "int64";
        case DiskType::F32:
            return "float32";
        case DiskType::F64:
            return "float64";
    }
    return "?";
}

VoxelType stored_type(DiskType t) {
    switch (t) {
        case DiskType::U8:
            return VoxelType::UInt8;
        case DiskType::I8:
        case DiskType::I16:
            return VoxelType::Int16;
        case DiskType::U16:
            return VoxelType::UInt16;
        default:
            return VoxelType::Float32;
    }
}

DiskType disk_type_of(VoxelType t) {
    switch (t) {
        case VoxelType::UInt8:
            return DiskType::U8;
        case VoxelType::Int16:
            return DiskType::I16;
        case VoxelType::UInt16:
            return DiskType::U16;
        case VoxelType::Float32:
            return DiskType::F32;
    }
    return DiskType::U8;
}

namespace {

template <class Src, class Dst>
void convert_typed(const Src* in, size_t count, Dst* out, bool rescale, double slope,
                   double intercept) {
    if (rescale) {
        for (size_t i = 0; i < count; ++i) out[i] = Dst(double(in[i]) * slope + intercept);
    } else {
        for (size_t i = 0; i < count; ++i) out[i] = Dst(in[i]);
    }
}

template <class Dst>
void convert_to(DiskType src, const void* in, size_t count, Dst* out, bool rescale, double slope,
                double intercept) {
    switch (src) {
        case DiskType::U8:
            return convert_typed(static_cast<const uint8_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::I8:
            return convert_typed(static_cast<const int8_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::U16:
            return convert_typed(static_cast<const uint16_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::I16:
            return convert_typed(static_cast<const int16_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::U32:
            return convert_typed(static_cast<const uint32_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::I32:
            return convert_typed(static_cast<const int32_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::U64:
            return convert_typed(static_cast<const uint64_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::I64:
            return convert_typed(static_cast<const int64_t*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::F32:
            return convert_typed(static_cast<const float*>(in), count, out, rescale, slope,
                                 intercept);
        case DiskType::F64:
            return convert_typed(static_cast<const double*>(in), count, out, rescale, slope,
                                 intercept);
    }
}

}  // namespace

void convert_voxels(DiskType src, const void* in, size_t count, Volume& v, size_t first,
                    bool rescale, double slope, double intercept) {
    switch (v.type()) {
        case VoxelType::UInt8:
            return convert_to(src, in, count, v.data_as<uint8_t>() + first, rescale, slope,
                              intercept);
        case VoxelType::Int16:
            return convert_to(src, in, count, v.data_as<int16_t>() + first, rescale, slope,
                              intercept);
        case VoxelType::UInt16:
            return convert_to(src, in, count, v.data_as<uint16_t>() + first, rescale, slope,
                              intercept);
        case VoxelType::Float32:
            return convert_to(src, in, count, v.data_as<float>() + first, rescale, slope,
                              intercept);
    }
}

void swap_bytes(void* data, size_t count, size_t elem_size) {
    if (elem_size <= 1) return;
    auto* p = static_cast<uint8_t*>(data);
    for (size_t i = 0; i < count; ++i, p += elem_size) std::reverse(p, p + elem_size);
}

void read_voxel_stream(const std::function<size_t(void*, size_t)>& read, DiskType disk, bool swap,
                       Volume& v, const std::string& where,
                       const std::function<void(double)>& progress, bool rescale, double slope,
                       double intercept) {
    const size_t count = v.voxel_count();
    const size_t elem = disk_type_size(disk);
    const size_t total = count * elem;
    auto truncated = [&](size_t got) {
        return Error(where, "voxel data",
                     "truncated: expected " + std::to_string(total) + " bytes of " +
                         to_string(disk) + " voxels, the data ends after " + std::to_string(got));
    };
    const bool direct = !rescale && disk == disk_type_of(v.type());
    if (direct) {
        // Straight into the volume's buffer, in chunks so progress can be reported.
        constexpr size_t kChunk = size_t(64) << 20;
        auto* dst = static_cast<uint8_t*>(v.data());
        size_t done = 0;
        while (done < total) {
            const size_t want = std::min(kChunk, total - done);
            const size_t got = read(dst + done, want);
            done += got;
            if (got < want) throw truncated(done);
            report(progress, 0.95 * double(done) / double(total));
        }
        if (swap) swap_bytes(v.data(), count, elem);
        return;
    }
    // Converting: stage a few MiB of file voxels at a time.
    constexpr size_t kStageVoxels = size_t(1) << 20;
    std::vector<uint8_t> stage(std::min(count, kStageVoxels) * elem);
    size_t first = 0;
    while (first < count) {
        const size_t n = std::min(kStageVoxels, count - first);
        const size_t got = read(stage.data(), n * elem);
        if (got < n * elem) throw truncated(first * elem + got);
        if (swap) swap_bytes(stage.data(), n, elem);
        convert_voxels(disk, stage.data(), n, v, first, rescale, slope, intercept);
        first += n;
        report(progress, 0.95 * double(first) / double(count));
    }
}

}  // namespace lacuna::io
