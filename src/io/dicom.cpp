// DICOM series: a folder of single-frame slices (or one multi-frame file).
//
// Reading goes file by file through GDCMImageIO into the volume's own buffer (one slice of
// staging at most), instead of itk::ImageSeriesReader, which would allocate its own full-size
// image. GDCMSeriesFileNames groups and sorts the files; the slice spacing is measured from the
// Image Position (Patient) of the first and last slices along the slice normal, like ITK does.
//
// Why GDCM in a child process (isolated.h), not DCMTK: GDCM asserts and over-allocates on
// damaged files, and DCMTK (Debian's libdcmtk-dev 3.6.7) would replace the series grouping,
// sorting, geometry and the decompression codecs GDCM gives us through ITK with hand-written
// code of our own. Running the GDCM reader in a forked child keeps all of that and turns every
// failure (an exception, an abort, a segfault, a capped allocation) into one error line; the
// voxels come back through shared memory, without a copy. Before GDCM sees anything the folder
// itself is checked in the parent: every entry must be a regular file (or a subfolder, which is
// not read), so a symlink to /dev/zero is an error, not a silently dropped slice. After reading,
// the slice positions are checked: no duplicates, no gaps (docs/formats.md, "DICOM folders").
//
// Writing (tests, conversions) emits MR Image Storage slices, which carry position,
// orientation and spacing; secondary-capture objects would drop them. The slices are written
// by a child process into a temporary folder beside the target, which is renamed into place
// once every slice is on disk.
#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkMetaDataObject.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include "io/dicom_check.h"
#include "io/isolated.h"
#include "io/itk_support.h"
#include "io/readers.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace {

namespace fs = std::filesystem;

std::string file_name(const std::string& file) {
    return fs::path(file).filename().string();
}

const char* kind_of(mode_t m) {
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISSOCK(m)) return "a socket";
    return "not a regular file";
}

// Every entry of the folder must be a regular file, a symlink to one, or a subfolder (not
// read: GDCMSeriesFileNames does not recurse). Anything else would be read by GDCM as a slice
// (a device never ends) or silently skipped: both are errors here.
void check_folder_entries(const std::string& dir) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string path = it->path().string(), name = it->path().filename().string();
        struct stat st {};
        if (::stat(path.c_str(), &st) != 0) {
            struct stat lst {};
            if (::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode))
                throw Error(dir, name, "is a symbolic link to nothing (expected DICOM slices)");
            throw Error(dir, name, std::string("cannot read: ") + std::strerror(errno));
        }
        if (S_ISDIR(st.st_mode) || S_ISREG(st.st_mode)) continue;
        throw Error(dir, name,
                    std::string("is ") + kind_of(st.st_mode) +
                        ", expected only DICOM slice files in the folder");
    }
    if (ec) throw Error(dir, "DICOM series", "cannot list the folder: " + ec.message());
}

struct SeriesFiles {
    std::vector<std::string> files;  // the series read: the one with the most slices
    std::set<std::string> in_any;    // every file GDCM put into some series (normalised paths)
};

SeriesFiles series_files(const std::string& dir) {
    try {
        auto names = itk::GDCMSeriesFileNames::New();
        names->SetUseSeriesDetails(true);
        names->SetDirectory(dir);
        const std::vector<std::string> uids = names->GetSeriesUIDs();
        SeriesFiles out;
        // Several series in one folder: take the one with the most slices.
        for (const auto& uid : uids) {
            std::vector<std::string> files = names->GetFileNames(uid);
            for (const auto& f : files) out.in_any.insert(fs::path(f).lexically_normal().string());
            if (files.size() > out.files.size()) out.files = std::move(files);
        }
        return out;
    } catch (const std::exception& e) {
        throw Error(dir, "DICOM series", itk_message(e));
    }
}

struct SliceInfo {
    unsigned nx = 0, ny = 0, nz = 0;
    DiskType disk = DiskType::U8;
    Vec3d origin, spacing;
    double direction[9] = {};
    bool has_position = false;  // Image Position (Patient) present
    int bits_allocated = 0;     // (0028,0100) as stored, before GDCM's rescaling
};

// ImageOrientationPatient (0020,0037) as GDCM judges it: six numbers, two rows of unit length
// within 1e-3 and perpendicular within 1e-3, after normalising them if they were not unit. Where
// GDCM finds no such pair it puts 1\0\0\0\1\0 in its place without a word (ITK reads that), so
// a zero, singular or non-finite orientation read as an axial LPS slice: an error here instead
// (issue 14, bad input), naming the slice and the field. An absent or empty field is left to
// GDCM (secondary captures carry none).
void check_orientation(const std::string& text, const std::string& file, const std::string& dir) {
    std::string t = text;
    while (!t.empty() && (t.back() == ' ' || t.back() == '\0')) t.pop_back();
    if (t.find_first_not_of(' ') == std::string::npos) return;
    std::vector<double> v;
    std::stringstream parts(t);
    bool numbers = true;
    for (std::string p; std::getline(parts, p, '\\');) {
        p = trim(p);
        char* end = nullptr;
        const double x = std::strtod(p.c_str(), &end);
        numbers = numbers && !p.empty() && end && *end == '\0' && std::isfinite(x);
        v.push_back(x);
    }
    const std::string shown = "ImageOrientationPatient is '" + one_line(t, 80) + "'";
    if (!numbers || v.size() != 6)
        throw Error(dir, file_name(file),
                    shown + ": expected six finite direction cosines (a row and a column)");
    const double n1 = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]),
                 n2 = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]);
    if (!(n1 > 0) || !(n2 > 0))
        throw Error(dir, file_name(file),
                    shown + ": a zero " + (n1 > 0 ? "column" : "row") +
                        " direction (a zero or singular orientation)");
    const double cosine = (v[0] * v[3] + v[1] * v[4] + v[2] * v[5]) / (n1 * n2);
    if (!(std::fabs(cosine) < 1e-3))
        throw Error(dir, file_name(file),
                    shown + ": the row and column directions are not perpendicular (cos " +
                        std::to_string(cosine) + "): a singular or sheared orientation");
}

// Reads one file's header into `io` (which is then ready for Read). Runs in the child.
SliceInfo read_slice_info(itk::GDCMImageIO& io, const std::string& file, const std::string& dir) {
    SliceInfo s;
    try {
        io.SetFileName(file);
        io.ReadImageInformation();
    } catch (const std::exception& e) {
        throw Error(dir, file_name(file), itk_message(e));
    }
    const unsigned nd = io.GetNumberOfDimensions();
    if (io.GetNumberOfComponents() != 1)
        throw Error(dir, file_name(file),
                    "expected a scalar image, got " + std::to_string(io.GetNumberOfComponents()) +
                        " components");
    s.nx = unsigned(io.GetDimensions(0));
    s.ny = nd > 1 ? unsigned(io.GetDimensions(1)) : 1;
    s.nz = nd > 2 ? unsigned(io.GetDimensions(2)) : 1;
    s.disk = disk_type_from_itk(io.GetComponentType(), dir);
    for (unsigned a = 0; a < 3 && a < nd; ++a) {
        s.origin[int(a)] = io.GetOrigin(a);
        s.spacing[int(a)] = io.GetSpacing(a);
        const std::vector<double> col = io.GetDirection(a);
        for (unsigned r = 0; r < 3 && r < col.size(); ++r) s.direction[r * 3 + a] = col[r];
    }
    std::string text;
    if (itk::ExposeMetaData<std::string>(io.GetMetaDataDictionary(), "0020|0037", text))
        check_orientation(text, file, dir);
    s.has_position =
        itk::ExposeMetaData<std::string>(io.GetMetaDataDictionary(), "0020|0032", text);
    if (itk::ExposeMetaData<std::string>(io.GetMetaDataDictionary(), "0028|0100", text))
        s.bits_allocated = std::atoi(text.c_str());
    return s;
}

// GDCM returns a slice whose Pixel Data is shorter than its image silently short: compare the
// walked length (dicom_check.h) with what rows x columns x frames x BitsAllocated need.
void check_pixel_length(const SliceInfo& s, const DicomWalk& w, const std::string& file,
                        const std::string& dir) {
    if (w.pixel_data_length < 0 ||
        (s.bits_allocated != 8 && s.bits_allocated != 16 && s.bits_allocated != 32))
        return;
    const uint64_t need = uint64_t(s.nx) * s.ny * s.nz * uint64_t(s.bits_allocated / 8);
    if (uint64_t(w.pixel_data_length) < need)
        throw Error(dir, file_name(file),
                    "Pixel Data holds " + std::to_string(w.pixel_data_length) + " bytes, a " +
                        std::to_string(s.nx) + "x" + std::to_string(s.ny) + "x" +
                        std::to_string(s.nz) + " image of " + std::to_string(s.bits_allocated) +
                        "-bit pixels needs " + std::to_string(need));
}

void read_slice_voxels(itk::GDCMImageIO& io, const SliceInfo& s, Volume& v, size_t first_voxel,
                       const std::string& file, const std::string& dir) {
    itk::ImageIORegion region(io.GetNumberOfDimensions());
    for (unsigned a = 0; a < io.GetNumberOfDimensions(); ++a) {
        region.SetIndex(a, 0);
        region.SetSize(a, io.GetDimensions(a));
    }
    io.SetIORegion(region);
    const size_t count = size_t(s.nx) * s.ny * s.nz;
    try {
        if (s.disk == disk_type_of(v.type())) {
            io.Read(static_cast<uint8_t*>(v.data()) + first_voxel * voxel_size(v.type()));
        } else {
            std::vector<uint8_t> stage(count * disk_type_size(s.disk));
            io.Read(stage.data());
            convert_voxels(s.disk, stage.data(), count, v, first_voxel);
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(dir, file_name(file), itk_message(e));
    }
}

std::string dims_string(unsigned x, unsigned y, unsigned z) {
    return std::to_string(x) + "x" + std::to_string(y) + "x" + std::to_string(z);
}

std::string mm(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g mm", x);
    return buf;
}

// Orders the slices along the normal (GDCM falls back to file names when positions repeat)
// and moves their voxels to match, one slice of scratch at a time (cycle by cycle).
void sort_slices(std::vector<SliceInfo>& slices, std::vector<std::string>& files, Volume& v,
                 const Vec3d& normal) {
    const size_t n = slices.size();
    std::vector<double> p(n);
    for (size_t i = 0; i < n; ++i) p[i] = dot(slices[i].origin - slices[0].origin, normal);
    std::vector<size_t> order(n);  // order[k]: the slice that belongs at z = k
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return p[a] < p[b]; });
    // Keep GDCM's direction when it was decreasing all along.
    if (std::is_sorted(p.begin(), p.end(), std::greater<double>())) return;
    if (std::is_sorted(order.begin(), order.end())) return;
    const size_t bytes = size_t(v.dims().x) * size_t(v.dims().y) * voxel_size(v.type());
    auto* base = static_cast<uint8_t*>(v.data());
    std::vector<uint8_t> scratch(bytes);
    std::vector<bool> done(n, false);
    for (size_t start = 0; start < n; ++start) {
        if (done[start] || order[start] == start) continue;
        std::memcpy(scratch.data(), base + start * bytes, bytes);
        size_t k = start;
        while (order[k] != start) {
            std::memcpy(base + k * bytes, base + order[k] * bytes, bytes);
            done[k] = true;
            k = order[k];
        }
        std::memcpy(base + k * bytes, scratch.data(), bytes);
        done[k] = true;
    }
    std::vector<SliceInfo> s2(n);
    std::vector<std::string> f2(n);
    for (size_t k = 0; k < n; ++k) {
        s2[k] = slices[order[k]];
        f2[k] = files[order[k]];
    }
    slices.swap(s2);
    files.swap(f2);
}

// Slice positions along the normal must step evenly: equal positions are duplicate slices, an
// uneven step is a missing (or extra) slice. 1% of the mean step (plus 1e-4 mm for positions
// printed with few digits) separates both from rounding. Slices without positions at all are
// accepted with the header's spacing (secondary captures); a mix is an error.
double checked_slice_step(const std::vector<SliceInfo>& slices,
                          const std::vector<std::string>& files, const Vec3d& normal,
                          const std::string& dir) {
    const size_t n = slices.size();
    std::vector<double> p(n);
    for (size_t i = 0; i < n; ++i) p[i] = dot(slices[i].origin - slices[0].origin, normal);
    const double step = (p[n - 1] - p[0]) / double(n - 1);
    // Duplicates first: one extra slice also makes every step uneven.
    for (size_t i = 1; i < n; ++i) {
        const double d = p[i] - p[i - 1];
        if (!std::isfinite(d))
            throw Error(dir, file_name(files[i]), "slice position is not a finite number");
        if (std::fabs(d) <= 1e-4)
            throw Error(dir, file_name(files[i]),
                        "duplicates the position of " + file_name(files[i - 1]) +
                            " (two slices at one position)");
    }
    for (size_t i = 1; i < n; ++i) {
        const double d = p[i] - p[i - 1];
        if (std::fabs(d - step) > 0.01 * std::fabs(step) + 1e-4)
            throw Error(dir, file_name(files[i]),
                        "is " + mm(std::fabs(d)) + " from " + file_name(files[i - 1]) +
                            ", the slices are " + mm(std::fabs(step)) +
                            " apart on average (a missing or extra slice?)");
    }
    // Each slice must lie on the line through the first along the normal: a position off it
    // (a tilted or sheared stack, or slices of another orientation) has no rigid index-to-world
    // map. The same tolerance as the step, across the normal.
    for (size_t i = 1; i < n; ++i) {
        const Vec3d off = slices[i].origin - slices[0].origin;
        const Vec3d across = off - normal * p[i];
        if (length(across) > 0.01 * std::fabs(step) * double(i) + 1e-3)
            throw Error(dir, file_name(files[i]),
                        "ImagePositionPatient is " + mm(length(across)) +
                            " off the slice normal "
                            "through " +
                            file_name(files[0]) +
                            " (contradictory slice positions: a sheared or tilted stack)");
    }
    return step;
}

// Whether the slices carry positions: all (checked), none (header spacing), or a mix (error).
bool slices_have_positions(const std::vector<SliceInfo>& slices,
                           const std::vector<std::string>& files, const std::string& dir) {
    size_t with = 0;
    for (const auto& s : slices) with += s.has_position;
    if (with == 0) return false;
    for (size_t i = 0; i < slices.size(); ++i)
        if (!slices[i].has_position)
            throw Error(dir, file_name(files[i]),
                        "has no Image Position (Patient), the other slices do");
    return true;
}

// What the child sends back with the voxels ('R' message): plain data, native layout.
struct SeriesHeader {
    int32_t dims[3];
    uint8_t type;
    double origin[3], spacing[3], direction[9];
};

// Memory the child may use beyond the volume: GDCM's parser, one slice of staging, ITK.
constexpr uint64_t kChildSlack = uint64_t(256) << 20;

// The child's side: reads the series with GDCM into the memfd and sends the header.
void read_series_child(const std::string& dir, const MemoryBudget& budget, int memfd,
                       ChildChannel& ch) {
    ch.limit_memory(kChildSlack);  // scanning headers needs little; a damaged length fails here
    // Every file's lengths are walked before GDCM's scanner reads any of them.
    std::map<std::string, DicomWalk> walks;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (!it->is_regular_file(ec)) continue;
        ch.working_on(it->path().string());
        walks[fs::path(it->path()).lexically_normal().string()] =
            walk_dicom_file(it->path().string(), dir);
    }
    const auto walk_of = [&](const std::string& file) {
        const auto w = walks.find(fs::path(file).lexically_normal().string());
        return w == walks.end() ? DicomWalk{} : w->second;
    };
    SeriesFiles series = series_files(dir);
    std::vector<std::string>& files = series.files;
    if (files.empty()) throw Error(dir, "DICOM series", "no DICOM series found in this folder");
    // GDCM's scanner skips files it cannot parse: a damaged slice would vanish from the series
    // without a word. A file that claims to be DICOM ("DICM" at byte 128, a first tag GDCM
    // reads as DICOM, or named .dcm) and is in no series is an error; other files (notes,
    // thumbnails) are ignored.
    for (const auto& [path, walk] : walks)
        if ((walk.part10 || walk.dicom ||
             to_lower(fs::path(path).extension().string()) == ".dcm") &&
            !series.in_any.count(path))
            throw Error(dir, file_name(path),
                        "is a DICOM file that GDCM could not place in any series (damaged?)");

    auto io = itk::GDCMImageIO::New();
    ch.working_on(files[0]);
    std::vector<SliceInfo> slices{read_slice_info(*io, files[0], dir)};
    check_pixel_length(slices[0], walk_of(files[0]), files[0], dir);
    const SliceInfo first = slices[0];  // a copy: slices grows below
    const bool multi_frame = files.size() == 1;
    if (!multi_frame && first.nz != 1)
        throw Error(dir, "DICOM series", "mixes multi-frame files into a slice series");
    const unsigned nz =
        multi_frame ? first.nz : unsigned(std::min<size_t>(files.size(), UINT32_MAX));
    if (first.nx < 2 || first.ny < 2 || nz < 2 || first.nx > unsigned(kMaxDim) ||
        first.ny > unsigned(kMaxDim) || nz > unsigned(kMaxDim))
        throw Error(dir, "dims",
                    "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                        dims_string(first.nx, first.ny, nz) +
                        (nz < 2 ? " (a single slice is not a volume)" : ""));
    const Vec3i dims{int(first.nx), int(first.ny), int(nz)};
    const VoxelType type = stored_type(first.disk);
    const uint64_t bytes = grid_bytes(dims, voxel_size(type));
    const uint64_t slice_stage = grid_bytes({dims.x, dims.y, 1}, disk_type_size(first.disk));
    check_budget(dir, "dims", io::dims_string(dims) + " " + to_string(first.disk),
                 sat_add(bytes, slice_stage), budget);
    // GDCM reading one slice may allocate that slice (twice, while decoding) and no more.
    ch.limit_memory(sat_add(sat_add(bytes, 4 * slice_stage), kChildSlack));

    if (::ftruncate(memfd, off_t(bytes)) != 0)
        throw Error(dir, "memory",
                    std::string("cannot allocate the volume: ") + std::strerror(errno));
    void* data = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, memfd, 0);
    if (data == MAP_FAILED)
        throw Error(dir, "memory", std::string("cannot map the volume: ") + std::strerror(errno));
    Volume v(dims, type, std::shared_ptr<void>(), data);

    const size_t slice_voxels = size_t(first.nx) * first.ny;
    read_slice_voxels(*io, first, v, 0, files[0], dir);
    ch.progress(0.9 / double(files.size()));
    for (size_t i = 1; i < files.size(); ++i) {
        ch.working_on(files[i]);
        slices.push_back(read_slice_info(*io, files[i], dir));
        const SliceInfo& s = slices.back();
        check_pixel_length(s, walk_of(files[i]), files[i], dir);
        const std::string name = file_name(files[i]);
        if (s.nx != first.nx || s.ny != first.ny || s.nz != 1)
            throw Error(dir, name,
                        "slice is " + dims_string(s.nx, s.ny, s.nz) + ", the first slice is " +
                            dims_string(first.nx, first.ny, 1));
        if (stored_type(s.disk) != type)
            throw Error(dir, name,
                        "slice voxels are " + to_string(s.disk) + ", the first slice's are " +
                            to_string(first.disk));
        read_slice_voxels(*io, s, v, i * slice_voxels, files[i], dir);
        ch.progress(0.9 * double(i + 1) / double(files.size()));
    }

    const Vec3d normal{first.direction[2], first.direction[5], first.direction[8]};
    const bool positioned = !multi_frame && slices_have_positions(slices, files, dir);
    if (positioned) sort_slices(slices, files, v, normal);
    SeriesHeader h{};
    for (int a = 0; a < 3; ++a) {
        h.dims[a] = dims[a];
        h.origin[a] = slices[0].origin[a];
        h.spacing[a] = first.spacing[a];
    }
    for (int i = 0; i < 9; ++i) h.direction[i] = first.direction[i];
    if (positioned) {
        // Slice spacing: the even step along the normal (direction column 2).
        const double along = checked_slice_step(slices, files, normal, dir);
        if (std::isfinite(along) && std::fabs(along) > 1e-6) {
            h.spacing[2] = std::fabs(along);
            if (along < 0)
                for (int r = 0; r < 3; ++r) h.direction[r * 3 + 2] = -h.direction[r * 3 + 2];
        }
    }
    h.type = uint8_t(type);
    ::munmap(data, bytes);
    ch.send('R', &h, sizeof h);
}

// A DICOM UID under the "2.25." (UUID-derived) root: digits only, at most 64 characters.
std::string make_uid(std::mt19937_64& rng) {
    return "2.25." + std::to_string(rng() >> 1) + std::to_string(rng() % 100000000000ull);
}

}  // namespace

Volume read_dicom_dir(const std::string& dir, const ReadOptions& opts) {
    init_itk();  // in the parent, so every child starts with the factories registered
    check_folder_entries(dir);
    const int memfd = ::memfd_create("lacuna-dicom", MFD_CLOEXEC);
    if (memfd < 0)
        throw Error(dir, "memory",
                    std::string("cannot create shared memory: ") + std::strerror(errno));
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{memfd};

    SeriesHeader h{};
    bool got = false;
    run_isolated(
        dir, "DICOM series", "the DICOM reader (GDCM)",
        [&](ChildChannel& ch) { read_series_child(dir, opts.max_memory, memfd, ch); },
        [&](char tag, const std::string& payload) {
            if (tag == 'R' && payload.size() == sizeof h) {
                std::memcpy(&h, payload.data(), sizeof h);
                got = true;
            }
        },
        opts.progress);
    if (!got || h.type > uint8_t(VoxelType::Float32))
        throw Error(dir, "DICOM series", "the reader returned no volume");

    const Vec3i dims{h.dims[0], h.dims[1], h.dims[2]};
    const VoxelType type = VoxelType(h.type);
    const uint64_t bytes = grid_bytes(dims, voxel_size(type));
    struct stat st {};
    if (::fstat(memfd, &st) != 0 || uint64_t(st.st_size) != bytes)
        throw Error(dir, "DICOM series", "the reader returned a volume of the wrong size");
    void* data = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, memfd, 0);
    if (data == MAP_FAILED)
        throw Error(dir, "memory", std::string("cannot map the volume: ") + std::strerror(errno));
    std::shared_ptr<void> owner(data, [bytes](void* p) { ::munmap(p, bytes); });
    Volume v(dims, type, owner, data);
    for (int a = 0; a < 3; ++a) {
        v.origin[a] = h.origin[a];
        v.spacing[a] = h.spacing[a];
    }
    for (int i = 0; i < 9; ++i) v.direction[i] = h.direction[i];
    v.geometry_source =
        "DICOM ImageOrientationPatient and ImagePositionPatient (read by GDCM, LPS), slices "
        "ordered along the normal";
    return v;
}

namespace {

// The child's side of write_dicom_dir: one file per z slice into `dir`.
void write_slices_child(const std::string& dir, const std::string& where, const Volume& v,
                        ChildChannel& ch) {
    std::mt19937_64 rng(std::random_device{}());
    const std::string study = make_uid(rng), series = make_uid(rng), frame = make_uid(rng);
    const Vec3i d = v.dims();
    const size_t slice_bytes = size_t(d.x) * size_t(d.y) * voxel_size(v.type());
    auto fmt = [](double x) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.6g", x);
        return std::string(buf);
    };
    const Vec3d col_z{v.direction[2], v.direction[5], v.direction[8]};
    std::string orientation;  // row (i axis) then column (j axis) direction cosines
    for (int a = 0; a < 2; ++a)
        for (int r = 0; r < 3; ++r)
            orientation += (orientation.empty() ? "" : "\\") + fmt(v.direction[r * 3 + a]);

    for (int k = 0; k < d.z; ++k) {
        const Vec3d pos = v.origin + col_z * (v.spacing.z * double(k));
        char name[32];
        std::snprintf(name, sizeof name, "slice_%05d.dcm", k);
        const std::string file = (fs::path(dir) / name).string();
        ch.working_on(file);

        auto io = itk::GDCMImageIO::New();
        io->KeepOriginalUIDOn();
        itk::MetaDataDictionary& dict = io->GetMetaDataDictionary();
        auto set = [&dict](const char* tag, const std::string& value) {
            itk::EncapsulateMetaData<std::string>(dict, tag, value);
        };
        set("0008|0016", "1.2.840.10008.5.1.4.1.1.4");  // MR Image Storage
        set("0008|0018", make_uid(rng));                // SOP instance
        set("0008|0060", "MR");
        set("0020|000d", study);
        set("0020|000e", series);
        set("0020|0052", frame);
        set("0020|0013", std::to_string(k + 1));
        set("0020|0032", fmt(pos.x) + "\\" + fmt(pos.y) + "\\" + fmt(pos.z));
        set("0020|0037", orientation);
        set("0018|0050", fmt(v.spacing.z));
        set("0028|0030", fmt(v.spacing.y) + "\\" + fmt(v.spacing.x));

        io->SetNumberOfDimensions(3);
        itk::ImageIORegion region(3);
        const unsigned size[3] = {unsigned(d.x), unsigned(d.y), 1};
        for (unsigned a = 0; a < 3; ++a) {
            io->SetDimensions(a, size[a]);
            io->SetSpacing(a, v.spacing[int(a)]);
            io->SetOrigin(a, pos[int(a)]);
            std::vector<double> col(3);
            for (unsigned r = 0; r < 3; ++r) col[r] = v.direction[r * 3 + a];
            io->SetDirection(a, col);
            region.SetIndex(a, 0);
            region.SetSize(a, size[a]);
        }
        io->SetPixelType(itk::IOPixelEnum::SCALAR);
        io->SetComponentType(itk_component_of(v.type()));
        io->SetNumberOfComponents(1);
        io->SetIORegion(region);
        io->SetFileName(file);
        try {
            io->Write(static_cast<const uint8_t*>(v.data()) + size_t(k) * slice_bytes);
        } catch (const std::exception& e) {
            throw Error(where, "output",
                        "cannot write " + std::string(name) + ": " + itk_message(e));
        }
        // GDCM may not notice a short write: every slice holds at least its voxels.
        expect_file_size(file, slice_bytes, where, true);
        sync_file(file, where);
    }
}

}  // namespace

void write_dicom_dir(const std::string& dir, const Volume& v) {
    init_itk();
    if (v.type() == VoxelType::Float32)
        throw Error(dir, "output",
                    "DICOM output supports uint8, int16 and uint16 volumes, not float32");
    // "out/series/" -> the folder "out/series", written as "out/.tmp-<pid>-<n>-series/" and
    // renamed into place complete. rename(2) replaces an empty folder, never a full one.
    std::string target = dir;
    while (target.size() > 1 && target.back() == '/') target.pop_back();
    std::error_code ec;
    if (fs::exists(target, ec) && !(fs::is_directory(target, ec) && fs::is_empty(target, ec)))
        throw Error(dir, "output",
                    "exists and is not an empty folder; DICOM output needs a new one");
    check_writable_dir(target);
    const TempName tmp = temp_name_beside(target);
    remove_stale_temp_files(tmp.dir);
    try {
        fs::create_directory(tmp.path, ec);
        if (ec) throw Error(dir, "output", "cannot create the folder: " + ec.message());
        run_isolated(
            dir, "output", "the DICOM writer (GDCM)",
            [&](ChildChannel& ch) { write_slices_child(tmp.path, dir, v, ch); },
            [](char, const std::string&) {}, {});
        sync_dir(tmp.path);
        rename_over(tmp.path, target);
        sync_dir(tmp.dir);
    } catch (...) {
        remove_temp_files(tmp);
        throw;
    }
}

}  // namespace lacuna::io
