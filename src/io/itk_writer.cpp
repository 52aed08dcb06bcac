// NRRD, NIfTI-1 and MetaImage output through ITK's ImageIO classes, straight from the volume's
// buffer, under a temporary name that is renamed into place once everything is on disk.
//
// Detached headers (.nhdr, .mhd) name their data file inside the header. ITK names it after
// the temporary header (".tmp-<pid>-<n>-vol.raw"), so after a successful write the data file is
// renamed to its final name ("vol.raw"), the header's reference is rewritten, and the header is
// renamed last: a reader never sees a new header that points at a missing data file.
#include <itkImageIOBase.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

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

std::string trim(const std::string& s) {
    const size_t b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return "";
    const size_t e = s.find_last_not_of(" \t\r");
    return s.substr(b, e - b + 1);
}

// Points the temporary detached header at the final data file name, renames the data file,
// then the header. `key` is "data file:" (NRRD) or "ElementDataFile" (MetaImage).
void finalize_detached(const TempName& tmp, const std::string& path, const std::string& ext) {
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
        std::ofstream hdr(tmp.path, std::ios::binary | std::ios::trunc);
        hdr << out;
        hdr.flush();
        if (!hdr) throw Error(path, "output", "cannot rewrite the detached header");
        hdr.close();
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
    rename_over(tmp.path, path);
}

}  // namespace

void write_itk(const std::string& path, const Volume& v) {
    init_itk();
    check_writable_dir(path);
    const std::string ext = format_extension(path);
    const TempName tmp = temp_name_beside(path);
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
        if (ext == ".nhdr" || ext == ".mhd")
            finalize_detached(tmp, path, ext);
        else
            rename_over(tmp.path, path);
    } catch (...) {
        remove_temp_files(tmp);
        throw;
    }
}

}  // namespace lacuna::io
