#include "cli_common.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "lacuna/error.h"
#include "lacuna/views.h"

namespace lacuna::cli {

void add_volume_args(CLI::App& cmd, VolumeArgs& a, bool required) {
    auto* opt = cmd.add_option("volume", a.path,
                               "Volume file (.nii .nii.gz .hdr/.img .nrrd .nhdr .mha .mhd .raw) or DICOM folder");
    if (required) opt->required();
    cmd.add_option("--dims", a.raw_dims, "Raw files: dimensions, e.g. 301x370x316");
    cmd.add_option("--type", a.raw_type, "Raw files: voxel type (uint8, int16, uint16, float32)");
    cmd.add_option("--range", a.range,
                   "Visualization range MIN:MAX mapped onto the TF domain (default: data range)");
    cmd.add_option("--max-memory", a.max_memory,
                   "Most memory a volume may take, e.g. 12G or 512MB (default: half of physical "
                   "memory, " +
                       format_bytes(default_memory_budget()) + " here)");
    cmd.add_flag("--allow-external-data", a.allow_external_data,
                 "Let a detached header (.nhdr, .mhd) name a data file outside its folder");
    cmd.add_option("--frame", a.frame,
                   "4D NIfTI files: which volume along the 4th axis (0-based; required when the "
                   "file holds several)");
    cmd.add_option("--spacing", a.spacing, "Raw files: voxel spacing X,Y,Z in mm (default 1,1,1)");
}

uint64_t parse_bytes(const std::string& s, const std::string& where) {
    const auto bad = [&] {
        return Error(where, "size",
                     "expected a size like 12G, 512MB, 1.5GiB or a byte count, got '" + s + "'");
    };
    size_t used = 0;
    double x = 0;
    try {
        x = std::stod(s, &used);
    } catch (const std::logic_error&) {
        throw bad();
    }
    std::string unit = s.substr(used);
    if (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
    static const std::pair<const char*, double> kUnits[] = {
        {"", 1},       {"B", 1},      {"k", 1e3},    {"K", 1e3},          {"kB", 1e3},
        {"KB", 1e3},   {"M", 1e6},    {"MB", 1e6},   {"G", 1e9},          {"GB", 1e9},
        {"T", 1e12},   {"TB", 1e12},  {"KiB", 1024}, {"MiB", 1048576.0}, {"GiB", 1073741824.0},
        {"TiB", 1099511627776.0}};
    for (const auto& [name, scale] : kUnits) {
        if (unit != name) continue;
        const double bytes = x * scale;
        if (!(bytes >= 1) || !(bytes < 1.8e19)) throw bad();
        return uint64_t(bytes);
    }
    throw bad();
}

Vec3d parse_spacing(const std::string& s, const std::string& where) {
    Vec3d sp{0, 0, 0};
    std::istringstream in(s);
    std::string part;
    int n = 0;
    while (std::getline(in, part, ',')) {
        size_t used = 0;
        double x = 0;
        try {
            x = std::stod(part, &used);
        } catch (const std::logic_error&) {
            used = 0;
        }
        if (n >= 3 || used == 0 || used != part.size() || !std::isfinite(x) || !(x > 0)) {
            n = -1;
            break;
        }
        sp[n++] = x;
    }
    if (n != 3)
        throw Error(where, "spacing", "expected three positive numbers X,Y,Z in mm, e.g. 0.5,0.5,1, got '" + s + "'");
    return sp;
}

Vec3i parse_dims(const std::string& s, const std::string& where) {
    Vec3i d{0, 0, 0};
    int n = 0;
    size_t pos = 0;
    for (int a = 0; a < 3; ++a) {
        size_t end = s.find_first_of("xX", pos);
        std::string part = s.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
        if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos ||
            part.size() > 9)
            break;
        d[a] = std::stoi(part);
        ++n;
        if (end == std::string::npos) break;
        pos = end + 1;
        if (a == 2) n = -1;  // trailing text after the third number
    }
    if (n != 3) throw Error(where, "dims", "expected AxBxC (e.g. 301x370x316), got '" + s + "'");
    return d;
}

Volume load_volume(const VolumeArgs& a) {
    ReadOptions ro;
    if (!a.raw_dims.empty() || !a.raw_type.empty()) {
        RawSpec spec;
        if (a.raw_dims.empty() || a.raw_type.empty())
            throw Error("--dims/--type", "raw layout", "give both --dims and --type for a raw file");
        spec.dims = parse_dims(a.raw_dims, "--dims");
        spec.type = parse_voxel_type(a.raw_type, "--type");
        ro.raw = spec;
    }
    if (!a.spacing.empty()) {
        // A raw file's layout comes from --dims/--type or its name; --spacing completes either.
        if (!ro.raw) ro.raw = raw_spec_from_name(a.path);
        if (!ro.raw || std::filesystem::path(a.path).extension() != ".raw")
            throw Error("--spacing", "spacing",
                        "applies to .raw files (other formats carry their own spacing); for a raw "
                        "file give --dims and --type or a name like head_181x217x181_uint8.raw");
        ro.raw->spacing = parse_spacing(a.spacing, "--spacing");
    }
    ro.frame = a.frame;
    if (!a.max_memory.empty()) ro.max_memory.bytes = parse_bytes(a.max_memory, "--max-memory");
    ro.max_memory.name = "--max-memory";
    ro.allow_external_data = a.allow_external_data;
    Progress progress("loading " + std::filesystem::path(a.path).filename().string());
    ro.progress = [&](double f) { progress.update(f); };
    Volume v = read_volume(a.path, ro);
    progress.done();
    if (!a.range.empty()) {
        size_t c = a.range.find(':');
        if (c == std::string::npos) throw Error("--range", "range", "expected MIN:MAX, got '" + a.range + "'");
        try {
            size_t used = 0;
            float lo = std::stof(a.range.substr(0, c), &used);
            if (used != c) throw std::invalid_argument("x");
            std::string rest = a.range.substr(c + 1);
            float hi = std::stof(rest, &used);
            if (used != rest.size()) throw std::invalid_argument("x");
            try {
                v.set_vis_range({lo, hi});
            } catch (const Error& e) {  // the library names the field; the user typed --range
                throw Error(std::string("--range: ") + e.what());
            }
        } catch (const std::logic_error&) {
            throw Error("--range", "range", "expected MIN:MAX numbers, got '" + a.range + "'");
        }
    }
    return v;
}

void check_output_path(const std::string& path, const std::string& ext) {
    namespace fs = std::filesystem;
    fs::path p(path);
    if (p.extension() != ext) throw Error(path, "output", "expected a " + ext + " file name");
    fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(path, "output", "folder '" + dir.string() + "' does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw Error(path, "output", "folder '" + dir.string() + "' is not writable");
    if (fs::is_directory(p, ec)) throw Error(path, "output", "is a folder");
}

Progress::Progress(std::string what)
    : m_what(std::move(what)), m_tty(::isatty(2)), m_start(std::chrono::steady_clock::now()) {
    if (m_tty) std::fprintf(stderr, "%s ...", m_what.c_str());
}

void Progress::update(double f) {
    if (m_tty && !m_done) std::fprintf(stderr, "\r%s ... %3d%%", m_what.c_str(), int(f * 100 + 0.5));
}

void Progress::done() {
    if (m_done) return;
    m_done = true;
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    if (m_tty) std::fprintf(stderr, "\r%s ... done in %.2f s\n", m_what.c_str(), s);
}

Progress::~Progress() {
    // Abandoned on an exception: end the line so the error message starts cleanly.
    if (m_tty && !m_done) std::fprintf(stderr, "\n");
}

void parse_view(const std::string& name, float& azimuth, float& elevation) {
    if (!named_view(name, azimuth, elevation))
        throw Error("--view", "view",
                    std::string("expected ") + kViewNames + ", got '" + name + "'");
}

}  // namespace lacuna::cli
