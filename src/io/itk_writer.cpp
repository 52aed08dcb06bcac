// NRRD, NIfTI-1 and MetaImage output through ITK's ImageIO classes, straight from the volume's
// buffer, under a temporary name that is renamed into place once everything is on disk.
//
// ITK's writers do not always report failure: NIfTI and MetaIO print a short write to std::cerr
// and return, so a full disk used to rename a truncated file into place. Every written file is
// therefore checked before the rename: the voxel bytes must all be there (the exact file size,
// after the header for attached formats; for .nii.gz the inflated size, which also checks the
// gzip CRC), then the file is fsync'ed.
//
// Detached headers (.nhdr, .mhd) name their data file inside the header. ITK names it after
// the temporary header (".tmp-<pid>-<n>-vol.raw"), so after a successful write the data file is
// renamed to its final name ("vol.raw"), the header's reference is rewritten, and the header is
// renamed last: a reader never sees a new header that points at a missing data file.
#include <itkImageIOBase.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>
#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/io_util.h"
#include "io/itk_support.h"
#include "io/readers.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace {

itk::ImageIOBase::Pointer make_writer_io(const std::string& ext) {
    if (ext == ".nrrd" || ext == ".nhdr") return itk::NrrdImageIO::New().GetPointer();
    if (ext == ".nii" || ext == ".nii.gz") return itk::NiftiImageIO::New().GetPointer();
    return itk::MetaImageIO::New().GetPointer();
}

// Points the temporary detached header at the final data file name, renames the data file,
// then the header. `key` is "data file:" (NRRD) or "ElementDataFile" (MetaImage).
void finalize_detached(const TempName& tmp, const std::string& path, const std::string& ext,
                       uint64_t data_bytes) {
    std::ifstream in(tmp.path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    in.close();
    std::istringstream lines(text.str());
    std::string line, out, data_tmp, data_final;
    while (std::getline(lines, line)) {
        std::string value;
        size_t cut = std::string::npos;
        if (ext == ".nhdr" && (line.rfind("data file:", 0) == 0 || line.rfind("datafile:", 0) == 0))
            cut = line.find(':');
        else if (ext == ".mhd" && line.rfind("ElementDataFile", 0) == 0)
            cut = line.find('=');
        if (cut != std::string::npos) {
            value = trim(line.substr(cut + 1));
            const std::filesystem::path ref(value);
            const std::string file = ref.filename().string();
            if (file.rfind(tmp.prefix, 0) == 0) {
                const std::string final_file = file.substr(tmp.prefix.size());
                const std::filesystem::path dir =
                    ref.parent_path().empty() ? std::filesystem::path(tmp.dir)
                                              : std::filesystem::path(tmp.dir) / ref.parent_path();
                data_tmp = (dir / file).string();
                data_final = (dir / final_file).string();
                const std::filesystem::path new_ref = ref.parent_path() / final_file;
                line = line.substr(0, cut + 1) + " " + new_ref.string();
            }
        }
        out += line;
        out += '\n';
    }
    if (!data_tmp.empty()) {
        expect_file_size(data_tmp, data_bytes, path);
        sync_file(data_tmp, path);
        {
            std::ofstream hdr(tmp.path, std::ios::binary | std::ios::trunc);
            hdr << out;
            hdr.flush();
            if (!hdr) throw Error(path, "output", "cannot rewrite the detached header");
        }
        expect_file_size(tmp.path, out.size(), path);
        sync_file(tmp.path, path);
        rename_over(data_tmp, data_final);
        try {
            rename_over(tmp.path, path);
        } catch (...) {
            // Without its header the renamed data file is debris.
            std::remove(data_final.c_str());
            throw;
        }
        return;
    }
    throw Error(path, "output", "cannot write: the detached header names no data file");
}

// Byte offset of the voxels in an attached header file written by ITK: after NRRD's blank
// line, or after MetaImage's "ElementDataFile = LOCAL" line. 0 if not found.
uint64_t attached_header_size(const std::string& file, const std::string& ext) {
    std::ifstream in(file, std::ios::binary);
    std::string head(size_t(1) << 16, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    if (ext == ".nrrd") {
        const size_t blank = head.find("\n\n");
        return blank == std::string::npos ? 0 : blank + 2;
    }
    const size_t key = head.find("ElementDataFile");
    const size_t eol = key == std::string::npos ? key : head.find('\n', key);
    return eol == std::string::npos ? 0 : eol + 1;
}

// Inflated size of a gzip file (gzread also checks the CRC and length in the trailer).
void expect_gzip_size(const std::string& file, uint64_t expected, const std::string& where) {
    gzFile f = gzopen(file.c_str(), "rb");
    if (!f) throw Error(where, "output", "cannot write: cannot reopen the written file");
    std::vector<char> buf(size_t(1) << 20);
    uint64_t total = 0;
    int got = 0;
    while ((got = gzread(f, buf.data(), unsigned(buf.size()))) > 0) total += uint64_t(got);
    int code = Z_OK;
    gzerror(f, &code);
    gzclose(f);
    if (got < 0 || (code != Z_OK && code != Z_STREAM_END) || total != expected)
        throw Error(where, "output",
                    "cannot write: the compressed file holds " + std::to_string(total) +
                        " bytes, expected " + std::to_string(expected) +
                        " (disk full or file size limit?)");
}

// Checks an attached file (.nrrd .nii .nii.gz .mha) holds all its voxels, then fsyncs it.
void verify_attached(const std::string& file, const std::string& ext, uint64_t data_bytes,
                     const std::string& where) {
    constexpr uint64_t kNiftiOffset = 352;  // ITK writes NIfTI-1 with vox_offset 352
    if (ext == ".nii") {
        expect_file_size(file, kNiftiOffset + data_bytes, where);
    } else if (ext == ".nii.gz") {
        expect_gzip_size(file, kNiftiOffset + data_bytes, where);
    } else {
        const uint64_t header = attached_header_size(file, ext);
        if (header == 0)
            throw Error(where, "output", "cannot write: the written header is incomplete");
        expect_file_size(file, header + data_bytes, where);
    }
    sync_file(file, where);
}

}  // namespace

void write_itk(const std::string& path, const Volume& v) {
    init_itk();
    check_writable_dir(path);
    const std::string ext = format_extension(path);
    const TempName tmp = temp_name_beside(path);
    remove_stale_temp_files(tmp.dir);
    try {
        itk::ImageIOBase::Pointer io = make_writer_io(ext);
        io->SetNumberOfDimensions(3);
        itk::ImageIORegion region(3);
        for (unsigned a = 0; a < 3; ++a) {
            io->SetDimensions(a, itk::SizeValueType(v.dims()[int(a)]));
            io->SetSpacing(a, v.spacing[int(a)]);
            io->SetOrigin(a, v.origin[int(a)]);
            std::vector<double> col(3);
            for (unsigned r = 0; r < 3; ++r) col[r] = v.direction[r * 3 + a];
            io->SetDirection(a, col);
            region.SetIndex(a, 0);
            region.SetSize(a, itk::SizeValueType(v.dims()[int(a)]));
        }
        io->SetPixelType(itk::IOPixelEnum::SCALAR);
        io->SetComponentType(itk_component_of(v.type()));
        io->SetNumberOfComponents(1);
        io->SetIORegion(region);
        // Compression only where the name asks for it (.nii.gz); niftilib also keys off
        // the name, which the temporary keeps.
        io->SetUseCompression(ext == ".nii.gz");
        io->SetFileName(tmp.path);
        {
            QuietStderr quiet;
            try {
                io->WriteImageInformation();
                io->Write(v.data());
            } catch (const std::exception& e) {
                std::string msg = itk_message(e);
                if (!quiet.text().empty()) msg += " (" + quiet.text() + ")";
                throw Error(path, "output", "cannot write: " + msg);
            }
        }
        if (ext == ".nhdr" || ext == ".mhd") {
            finalize_detached(tmp, path, ext, v.bytes());
        } else {
            verify_attached(tmp.path, ext, v.bytes(), path);
            rename_over(tmp.path, path);
        }
        sync_dir(tmp.dir);
    } catch (...) {
        remove_temp_files(tmp);
        throw;
    }
}

}  // namespace lacuna::io
