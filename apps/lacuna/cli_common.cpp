#include "cli_common.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "lacuna/error.h"
#include "lacuna/rgb.h"
#include "lacuna/views.h"

namespace lacuna::cli {

void add_volume_args(CLI::App& cmd, VolumeArgs& a, bool required) {
    auto* opt = cmd.add_option(
        "volume", a.path,
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
    cmd.add_option("--rgb-opacity", a.rgb_opacity,
                   "RGB/RGBA files: the scalar the TF's opacity and skipping read: luminance "
                   "(Rec. 709), r, g, b or a (colour always comes from the data)")
        ->capture_default_str();
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
    static const std::pair<const char*, double> kUnits[] = {{"", 1},
                                                            {"B", 1},
                                                            {"k", 1e3},
                                                            {"K", 1e3},
                                                            {"kB", 1e3},
                                                            {"KB", 1e3},
                                                            {"M", 1e6},
                                                            {"MB", 1e6},
                                                            {"G", 1e9},
                                                            {"GB", 1e9},
                                                            {"T", 1e12},
                                                            {"TB", 1e12},
                                                            {"KiB", 1024},
                                                            {"MiB", 1048576.0},
                                                            {"GiB", 1073741824.0},
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
        throw Error(where, "spacing",
                    "expected three positive numbers X,Y,Z in mm, e.g. 0.5,0.5,1, got '" + s + "'");
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

ValueRange parse_range(const std::string& range) {
    const size_t c = range.find(':');
    if (c == std::string::npos)
        throw Error("--range", "range", "expected MIN:MAX, got '" + range + "'");
    try {
        size_t used = 0;
        const float lo = std::stof(range.substr(0, c), &used);
        if (used != c) throw std::invalid_argument("x");
        const std::string rest = range.substr(c + 1);
        const float hi = std::stof(rest, &used);
        if (used != rest.size()) throw std::invalid_argument("x");
        return {lo, hi};
    } catch (const std::logic_error&) {
        throw Error("--range", "range", "expected MIN:MAX numbers, got '" + range + "'");
    }
}

std::optional<RawSpec> raw_spec_of(const VolumeArgs& a) {
    std::optional<RawSpec> raw;
    if (!a.raw_dims.empty() || !a.raw_type.empty()) {
        RawSpec spec;
        if (a.raw_dims.empty() || a.raw_type.empty())
            throw Error("--dims/--type", "raw layout",
                        "give both --dims and --type for a raw file");
        spec.dims = parse_dims(a.raw_dims, "--dims");
        spec.type = parse_voxel_type(a.raw_type, "--type");
        raw = spec;
    }
    if (!a.spacing.empty()) {
        // A raw file's layout comes from --dims/--type or its name; --spacing completes either.
        if (!raw) raw = raw_spec_from_name(a.path);
        if (!raw || std::filesystem::path(a.path).extension() != ".raw")
            throw Error("--spacing", "spacing",
                        "applies to .raw files (other formats carry their own spacing); for a raw "
                        "file give --dims and --type or a name like head_181x217x181_uint8.raw");
        raw->spacing = parse_spacing(a.spacing, "--spacing");
    }
    return raw;
}

Volume load_volume(const VolumeArgs& a) {
    ReadOptions ro;
    ro.raw = a.raw_spec ? a.raw_spec : raw_spec_of(a);
    ro.frame = a.frame;
    if (!a.max_memory.empty()) ro.max_memory.bytes = parse_bytes(a.max_memory, "--max-memory");
    ro.max_memory.name = "--max-memory";
    ro.allow_external_data = a.allow_external_data;
    Progress progress("loading " + std::filesystem::path(a.path).filename().string());
    ro.progress = [&](double f) { progress.update(f); };
    Volume v = read_volume(a.path, ro, parse_rgb_opacity(a.rgb_opacity, "--rgb-opacity"));
    progress.done();
    if (a.range_value || !a.range.empty()) {
        const ValueRange r = a.range_value ? *a.range_value : parse_range(a.range);
        try {
            v.set_vis_range(r);
        } catch (const Error& e) {  // the library names the field; the user typed --range
            throw Error(std::string("--range: ") + e.what());
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

namespace {
bool g_quiet = false;

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string plural(int64_t n, const std::string& unit) {
    return std::to_string(n) + " " + unit + (n == 1 ? "" : "s");
}
}  // namespace

void set_quiet(bool q) {
    g_quiet = q;
}
bool quiet() {
    return g_quiet;
}

Progress::Progress(std::string what)
    : m_what(std::move(what)),
      m_tty(::isatty(2) && !g_quiet),
      m_start(std::chrono::steady_clock::now()),
      m_last_draw(m_start) {
    draw(m_what + " ...", true);
}

Progress::Progress(std::string what, int64_t total, std::string unit)
    : m_what(std::move(what)),
      m_unit(std::move(unit)),
      m_total(std::max<int64_t>(total, 0)),
      m_tty(::isatty(2) && !g_quiet),
      m_start(std::chrono::steady_clock::now()),
      m_last_draw(m_start) {}

// A terminal line, redrawn at most ten times a second unless `force`; padded so a shorter line
// covers a longer one.
void Progress::draw(const std::string& line, bool force) {
    if (!m_tty || m_done) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && now - m_last_draw < std::chrono::milliseconds(100)) return;
    m_last_draw = now;
    std::fprintf(stderr, "\r%-60s", line.c_str());
    std::fflush(stderr);
    m_drawn = true;
}

void Progress::update(double f) {
    char pct[16];
    std::snprintf(pct, sizeof pct, "%3d%%", int(f * 100 + 0.5));
    draw(m_what + " ... " + pct, false);
}

void Progress::step(int64_t items_done) {
    m_items = items_done;
    if (m_total <= 0) return;
    const double s = seconds_since(m_start);
    char line[160];
    if (items_done > 0 && items_done < m_total)
        std::snprintf(line, sizeof line, "%s: %lld/%lld %ss, %.1f s, ETA %.1f s", m_what.c_str(),
                      (long long)items_done, (long long)m_total, m_unit.c_str(), s,
                      s / double(items_done) * double(m_total - items_done));
    else
        std::snprintf(line, sizeof line, "%s: %lld/%lld %ss, %.1f s", m_what.c_str(),
                      (long long)items_done, (long long)m_total, m_unit.c_str(), s);
    // The first count is drawn at once (the line appears), the last one too (it is complete).
    draw(line, !m_drawn || items_done == m_total);
}

void Progress::done() {
    if (m_done) return;
    const double s = seconds_since(m_start);
    char line[200];
    if (m_total < 0) {  // a fraction: the terminal's last word on the step
        std::snprintf(line, sizeof line, "%s ... done in %.2f s", m_what.c_str(), s);
        draw(line, true);
        if (m_tty) std::fprintf(stderr, "\n");
        m_done = true;
        return;
    }
    if (m_total == 0)
        std::snprintf(line, sizeof line, "%s: done in %.2f s", m_what.c_str(), s);
    else if (m_total == 1)
        std::snprintf(line, sizeof line, "%s: %s in %.2f s", m_what.c_str(),
                      plural(m_total, m_unit).c_str(), s);
    else
        std::snprintf(line, sizeof line, "%s: %s in %.2f s (%.1f ms/%s)", m_what.c_str(),
                      plural(m_total, m_unit).c_str(), s, s * 1e3 / double(m_total),
                      m_unit.c_str());
    if (m_tty) {
        draw(line, true);
        std::fprintf(stderr, "\n");
    } else if (!g_quiet) {
        std::fprintf(stderr, "%s\n", line);
    }
    m_done = true;
}

Progress::~Progress() {
    // Abandoned on an exception: end the line so the error message starts cleanly.
    if (m_drawn && !m_done) std::fprintf(stderr, "\n");
}

void parse_view(const std::string& name, float& azimuth, float& elevation) {
    if (!named_view(name, azimuth, elevation))
        throw Error("--view", "view",
                    std::string("expected ") + kViewNames + ", got '" + name + "'");
}

}  // namespace lacuna::cli
