// read_volume / write_volume: pick the format from the path, hand over to one reader or
// writer, and make sure nothing but lacuna::Error (one line, naming the file) escapes.
#include <filesystem>
#include <new>

#include "io/io_util.h"
#include "io/readers.h"
#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"
#include "lacuna/rgb.h"
#include "lacuna/volume_frames.h"

namespace lacuna {

Volume read_volume(const std::string& path, const ReadOptions& opts) {
    return read_volume(path, opts, RgbOpacity::Luminance);
}

Volume read_volume(const std::string& path, const ReadOptions& opts, RgbOpacity rgb_opacity) {
    io::report(opts.progress, 0.0);
    Volume v;
    try {
        std::error_code ec;
        const std::string e = io::format_extension(path);
        const bool nifti =
            e == ".nii" || e == ".nii.gz" || e == ".hdr" || e == ".img" || e == ".img.gz";
        if (opts.frame && *opts.frame != 0 && !nifti)
            throw Error(path, "frame",
                        "expected 0: this format is read as one volume (volumes are chosen in "
                        "4D NIfTI files), got " +
                            std::to_string(*opts.frame));
        if (!path.empty() && std::filesystem::is_directory(path, ec)) {
            v = io::read_dicom_dir(path, opts);
        } else {
            io::check_readable_file(path);
            const std::string ext = io::format_extension(path);
            if (nifti)  // .nii, .nii.gz and the two-file pairs .hdr + .img (or .img.gz)
                v = io::read_nifti(path, opts, rgb_opacity);
            else if (ext == ".raw")
                v = io::read_raw(path, opts);
            else
                v = io::read_itk(path, opts);
        }
        check_geometry(v, path);           // one world frame: no zero, singular or sheared axes
        v.replace_nan_with_minimum(path);  // NaN is background (docs/formats.md)
        v.compute_range(path);
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw Error(path, "memory", "out of memory while reading");
    } catch (const std::exception& e) {
        throw Error(path, "read", io::one_line(e.what()));
    }
    io::report(opts.progress, 1.0);
    return v;
}

int64_t count_volume_frames(const std::string& path) {
    const std::string e = io::format_extension(path);
    if (e != ".nii" && e != ".nii.gz" && e != ".hdr" && e != ".img" && e != ".img.gz") return 1;
    try {
        io::check_readable_file(path);
        return io::nifti_frames(path);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path, "read", io::one_line(e.what()));
    }
}

void write_volume(const std::string& path, const Volume& v) {
    if (!v.data()) throw Error(path, "output", "the volume is empty");
    try {
        if (!path.empty() && path.back() == '/') {
            io::write_dicom_dir(path, v);
            return;
        }
        const std::string ext = io::format_extension(path);
        if (ext == ".raw") {
            io::write_raw(path, v);
        } else if (ext == ".nrrd" || ext == ".nhdr" || ext == ".nii" || ext == ".nii.gz" ||
                   ext == ".mha" || ext == ".mhd") {
            io::write_itk(path, v);
        } else {
            throw Error(path, "output",
                        "unknown extension '" + ext +
                            "', expected .nrrd, .nhdr, .nii, .nii.gz, .mha, .mhd, .raw or a "
                            "directory ending in '/'");
        }
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw Error(path, "memory", "out of memory while writing");
    } catch (const std::exception& e) {
        throw Error(path, "output", io::one_line(e.what()));
    }
}

}  // namespace lacuna
