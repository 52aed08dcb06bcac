// NRRD (.nrrd/.nhdr) and MetaImage (.mha/.mhd) through ITK's ImageIO classes, used directly
// (no itk::Image, no pipeline): ITK parses the header, we validate it before allocating, then
// the voxels go straight into the volume's buffer — read by NrrdIO for NRRD, by our own code
// for MetaImage (metaimage_data.cpp explains why).
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkMetaImageIO.h>
#include <itkNrrdImageIO.h>

#include <memory>
#include <new>
#include <optional>

#include "io/detached_data.h"
#include "io/itk_support.h"
#include "io/metaimage_data.h"
#include "io/nrrd_data.h"
#include "io/readers.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace {

itk::ImageIOBase::Pointer make_reader_io(const std::string& path) {
    const std::string ext = format_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr") return itk::NrrdImageIO::New().GetPointer();
    if (ext == ".mha" || ext == ".mhd") return itk::MetaImageIO::New().GetPointer();
    // Unknown extension: let the registered factories guess from the content.
    return itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
}

std::string format_name(const std::string& path) {
    const std::string ext = format_extension(path);
    if (ext == ".nrrd" || ext == ".nhdr") return "NRRD";
    if (ext == ".mha" || ext == ".mhd") return "MetaImage";
    return "image";
}

// Reads the header and returns the 3D size; throws for anything lacuna cannot hold.
Vec3i checked_dims(itk::ImageIOBase& io, const std::string& path) {
    const unsigned nd = io.GetNumberOfDimensions();
    if (nd < 3 || nd > 4 || (nd == 4 && io.GetDimensions(3) != 1)) {
        // GetDimensions(i) does not check i: only ask for the nd that exist.
        std::string got;
        for (unsigned a = 0; a < nd; ++a)
            got += (a ? "x" : "") + std::to_string(io.GetDimensions(a));
        throw Error(path, "dims",
                    "expected a 3D volume, got a " + std::to_string(nd) + "D image" +
                        (got.empty() ? "" : " of " + got));
    }
    if (io.GetNumberOfComponents() != 1)
        throw Error(path, "pixel type",
                    "expected a scalar image, got " + std::to_string(io.GetNumberOfComponents()) +
                        " components (" +
                        itk::ImageIOBase::GetPixelTypeAsString(io.GetPixelType()) + ")");
    // Check before narrowing to int: sizes come from the file and may be anything.
    for (unsigned a = 0; a < 3; ++a) {
        const auto d = io.GetDimensions(a);
        if (d < 2 || d > itk::SizeValueType(kMaxDim))
            throw Error(path, "dims",
                        "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                            std::to_string(io.GetDimensions(0)) + "x" +
                            std::to_string(io.GetDimensions(1)) + "x" +
                            std::to_string(io.GetDimensions(2)));
    }
    return {int(io.GetDimensions(0)), int(io.GetDimensions(1)), int(io.GetDimensions(2))};
}

void copy_geometry(const itk::ImageIOBase& io, Volume& v) {
    for (unsigned a = 0; a < 3; ++a) {
        v.spacing[a] = io.GetSpacing(a);
        v.origin[a] = io.GetOrigin(a);
        const std::vector<double> col = io.GetDirection(a);
        for (unsigned r = 0; r < 3; ++r) v.direction[r * 3 + a] = r < col.size() ? col[r] : 0.0;
    }
}

// What copy_geometry read, for `lacuna info`: ITK turns NRRD's space/space directions/space
// origin and MetaImage's TransformMatrix/Offset into LPS direction and origin (a file without
// them reads as LPS identity, as in ITK-based tools).
std::string geometry_source(const std::string& path) {
    const std::string f = format_name(path);
    if (f == "NRRD") return "NRRD space directions and space origin (read by ITK, LPS)";
    if (f == "MetaImage") return "MetaImage TransformMatrix and Offset (read by ITK, LPS)";
    return "ITK image direction and origin (LPS)";
}

}  // namespace

Volume read_itk(const std::string& path, const ReadOptions& opts, VoxelLayout* header_only) {
    init_itk();
    // ITK's libraries print to std::cerr; capture it while ITK runs (never around our own
    // progress callback) and append it to the error if the call fails.
    std::optional<QuietStderr> quiet(std::in_place);
    auto fail = [&](const std::string& field, const std::string& what) {
        std::string msg = what;
        const std::string printed = quiet ? quiet->text() : std::string();
        if (!printed.empty() && msg.find(printed) == std::string::npos) msg += " (" + printed + ")";
        return Error(path, field, msg);
    };

    itk::ImageIOBase::Pointer io;
    try {
        io = make_reader_io(path);
    } catch (const std::exception& e) {
        throw fail("header", itk_message(e));
    }
    if (!io)
        throw Error(path, "format",
                    "unrecognised; expected .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, .raw, a DICOM "
                    "file or a folder of DICOM slices");
    bool readable = false;
    try {
        readable = io->CanReadFile(path.c_str());
    } catch (const std::exception&) {
    }
    if (!readable) throw fail("header", "not a valid " + format_name(path) + " file");

    // Our checks of the header run before ITK parses it (docs/formats.md): NDims for MetaIO,
    // and where a detached NRRD header's data files are.
    std::optional<MetaHeaderOrientation> meta_orientation;
    if (dynamic_cast<itk::MetaImageIO*>(io.GetPointer()))
        meta_orientation = check_metaimage_header(path);
    std::vector<std::string> nrrd_files;
    if (dynamic_cast<itk::NrrdImageIO*>(io.GetPointer())) {
        quiet.reset();
        nrrd_files = check_nrrd_data_files(path, opts.allow_external_data);
        check_nrrd_geometry(path);
        quiet.emplace();
    }
    try {
        io->SetFileName(path);
        io->ReadImageInformation();
    } catch (const std::exception& e) {
        throw fail("header", itk_message(e));
    }

    const Vec3i dims = checked_dims(*io, path);
    const DiskType disk = disk_type_from_itk(io->GetComponentType(), path);
    const size_t voxels = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
    // MetaImage and (raw or gzip) NRRD: locate the voxels ourselves (metaimage_data.cpp,
    // nrrd_data.cpp explain why) and, for uncompressed data, check the length before
    // allocating.
    const uint64_t data_bytes = grid_bytes(dims, disk_type_size(disk));
    const uint64_t volume_bytes = grid_bytes(dims, voxel_size(stored_type(disk)));
    const std::string what = dims_string(dims) + " " + to_string(disk);
    if (!header_only) check_budget(path, "dims", what, volume_bytes, opts.max_memory);
    std::optional<MetaDataLayout> meta;
    if (auto* mio = dynamic_cast<itk::MetaImageIO*>(io.GetPointer())) {
        MetaImage* mi = mio->GetMetaImagePointer();
        meta = metaimage_layout(path, mi->ElementDataFileName(), mi->HeaderSize(),
                                mi->CompressedData(), mi->BinaryData(),
                                mi->BinaryDataByteOrderMSB(), data_bytes, opts.allow_external_data);
    } else if (dynamic_cast<itk::NrrdImageIO*>(io.GetPointer())) {
        const bool big = io->GetByteOrder() == itk::IOByteOrderEnum::BigEndian;
        meta = nrrd_layout(path, nrrd_files, data_bytes, voxels,
                           disk_type_size(disk) > 1 && big != host_is_big_endian());
    }
    // Voxels NrrdIO reads and that need conversion pass through a full-size temporary.
    if (!header_only && !meta && disk != disk_type_of(stored_type(disk)))
        check_budget(path, "dims", what + " (converted through a temporary)",
                     sat_add(volume_bytes, data_bytes), opts.max_memory);

    Volume v = header_only ? Volume(dims, stored_type(disk), nullptr, nullptr)
                           : Volume(dims, stored_type(disk), path);
    copy_geometry(*io, v);
    v.geometry_source = geometry_source(path);
    if (dynamic_cast<itk::NrrdImageIO*>(io.GetPointer()) && apply_nrrd_las_space(path, v))
        v.geometry_source =
            "NRRD space directions and space origin (left-anterior-superior space, converted to "
            "LPS by lacuna)";
    if (meta_orientation) apply_anatomical_orientation(*meta_orientation, v, path);
    if (header_only) {
        *header_only = {};
        if (meta)
            *header_only = {meta->path, uint64_t(meta->offset), disk, meta->swap,
                            !meta->compressed};
        return v;
    }
    if (meta) {
        quiet.reset();
        read_metaimage_voxels(*meta, disk, v, path, opts.progress);
        return v;
    }

    itk::ImageIORegion region(io->GetNumberOfDimensions());
    for (unsigned a = 0; a < io->GetNumberOfDimensions(); ++a) {
        region.SetIndex(a, 0);
        region.SetSize(a, io->GetDimensions(a));
    }
    io->SetIORegion(region);
    try {
        if (disk == disk_type_of(v.type())) {
            io->Read(v.data());
        } else {
            // ITK cannot convert while reading, so other types go through a temporary of the
            // file's type (documented in docs/formats.md).
            const size_t bytes = voxels * disk_type_size(disk);
            std::unique_ptr<uint8_t[]> tmp(new (std::nothrow) uint8_t[bytes]);
            if (!tmp)
                throw Error(path, "memory",
                            "could not allocate " + std::to_string(bytes >> 20) +
                                " MiB to convert " + to_string(disk) + " voxels");
            io->Read(tmp.get());
            convert_voxels(disk, tmp.get(), voxels, v, 0);
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw fail("voxel data", itk_message(e));
    }
    return v;
}

}  // namespace lacuna::io
