// DICOM series: a folder of single-frame slices (or one multi-frame file).
//
// Reading goes file by file through GDCMImageIO into the volume's own buffer (one slice of
// staging at most), instead of itk::ImageSeriesReader, which would allocate its own full-size
// image. GDCMSeriesFileNames groups and sorts the files; the slice spacing is measured from the
// Image Position (Patient) of the first and last slices along the slice normal, like ITK does.
//
// Writing (tests, conversions) emits MR Image Storage slices, which carry position,
// orientation and spacing; secondary-capture objects would drop them.
#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkMetaDataObject.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>
#include <vector>

#include "io/itk_support.h"
#include "io/readers.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace {

std::vector<std::string> series_files(const std::string& dir) {
    QuietStderr quiet;
    try {
        auto names = itk::GDCMSeriesFileNames::New();
        names->SetUseSeriesDetails(true);
        names->SetDirectory(dir);
        const std::vector<std::string> uids = names->GetSeriesUIDs();
        std::vector<std::string> best;
        // Several series in one folder: take the one with the most slices.
        for (const auto& uid : uids) {
            std::vector<std::string> files = names->GetFileNames(uid);
            if (files.size() > best.size()) best = std::move(files);
        }
        return best;
    } catch (const std::exception& e) {
        throw Error(dir, "DICOM series", itk_message(e));
    }
}

struct SliceInfo {
    unsigned nx = 0, ny = 0, nz = 0;
    DiskType disk = DiskType::U8;
    Vec3d origin, spacing;
    double direction[9] = {};
};

// Reads one file's header into `io` (which is then ready for Read).
SliceInfo read_slice_info(itk::GDCMImageIO& io, const std::string& file, const std::string& dir) {
    QuietStderr quiet;
    SliceInfo s;
    try {
        io.SetFileName(file);
        io.ReadImageInformation();
    } catch (const std::exception& e) {
        throw Error(dir, std::filesystem::path(file).filename().string(), itk_message(e));
    }
    const unsigned nd = io.GetNumberOfDimensions();
    if (io.GetNumberOfComponents() != 1)
        throw Error(dir, std::filesystem::path(file).filename().string(),
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
    return s;
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
    QuietStderr quiet;
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
        throw Error(dir, std::filesystem::path(file).filename().string(), itk_message(e));
    }
}

std::string dims_string(unsigned x, unsigned y, unsigned z) {
    return std::to_string(x) + "x" + std::to_string(y) + "x" + std::to_string(z);
}

// A DICOM UID under the "2.25." (UUID-derived) root: digits only, at most 64 characters.
std::string make_uid(std::mt19937_64& rng) {
    return "2.25." + std::to_string(rng() >> 1) + std::to_string(rng() % 100000000000ull);
}

}  // namespace

Volume read_dicom_dir(const std::string& dir, const ReadOptions& opts) {
    init_itk();
    const std::vector<std::string> files = series_files(dir);
    if (files.empty()) throw Error(dir, "DICOM series", "no DICOM series found in this folder");

    auto io = itk::GDCMImageIO::New();
    const SliceInfo first = read_slice_info(*io, files[0], dir);
    const bool multi_frame = files.size() == 1;
    if (!multi_frame && first.nz != 1)
        throw Error(dir, "DICOM series", "mixes multi-frame files into a slice series");
    const unsigned nz = multi_frame ? first.nz : unsigned(files.size());
    if (first.nx < 2 || first.ny < 2 || nz < 2 || first.nx > unsigned(kMaxDim) ||
        first.ny > unsigned(kMaxDim) || nz > unsigned(kMaxDim))
        throw Error(dir, "dims",
                    "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                        dims_string(first.nx, first.ny, nz) +
                        (nz < 2 ? " (a single slice is not a volume)" : ""));

    Volume v({int(first.nx), int(first.ny), int(nz)}, stored_type(first.disk), dir);
    v.origin = first.origin;
    v.spacing = first.spacing;
    for (int i = 0; i < 9; ++i) v.direction[i] = first.direction[i];

    const size_t slice_voxels = size_t(first.nx) * first.ny;
    Vec3d last_origin = first.origin;
    read_slice_voxels(*io, first, v, 0, files[0], dir);
    report(opts.progress, 0.9 / double(files.size()));
    for (size_t i = 1; i < files.size(); ++i) {
        const SliceInfo s = read_slice_info(*io, files[i], dir);
        const std::string name = std::filesystem::path(files[i]).filename().string();
        if (s.nx != first.nx || s.ny != first.ny || s.nz != 1)
            throw Error(dir, name,
                        "slice is " + dims_string(s.nx, s.ny, s.nz) + ", the first slice is " +
                            dims_string(first.nx, first.ny, 1));
        if (stored_type(s.disk) != v.type())
            throw Error(dir, name,
                        "slice voxels are " + to_string(s.disk) + ", the first slice's are " +
                            to_string(first.disk));
        read_slice_voxels(*io, s, v, i * slice_voxels, files[i], dir);
        last_origin = s.origin;
        report(opts.progress, 0.9 * double(i + 1) / double(files.size()));
    }

    if (!multi_frame) {
        // Slice spacing: first-to-last distance along the normal (direction column 2).
        const Vec3d normal{v.direction[2], v.direction[5], v.direction[8]};
        const double along = dot(last_origin - first.origin, normal) / double(nz - 1);
        if (std::isfinite(along) && std::fabs(along) > 1e-6) {
            v.spacing.z = std::fabs(along);
            if (along < 0)
                for (int r = 0; r < 3; ++r) v.direction[r * 3 + 2] = -v.direction[r * 3 + 2];
        }
    }
    return v;
}

void write_dicom_dir(const std::string& dir, const Volume& v) {
    init_itk();
    if (v.type() == VoxelType::Float32)
        throw Error(dir, "output",
                    "DICOM output supports uint8, int16 and uint16 volumes, not float32");
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(dir, "output", "cannot create the directory: " + ec.message());

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
        const std::string file = (std::filesystem::path(dir) / name).string();

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
        QuietStderr quiet;
        try {
            io->Write(static_cast<const uint8_t*>(v.data()) + size_t(k) * slice_bytes);
        } catch (const std::exception& e) {
            throw Error(dir, "output", "cannot write " + std::string(name) + ": " + itk_message(e));
        }
    }
}

}  // namespace lacuna::io
