// Shared pieces of the lacuna CLI: the only place strings become typed options (STYLE.md 3).
#pragma once
#include <CLI/CLI.hpp>

#include <chrono>
#include <optional>
#include <string>

#include "lacuna/camera.h"
#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna::cli {

// Options shared by every command that loads a volume.
struct VolumeArgs {
    std::string path;
    std::string raw_dims;  // "301x370x316"
    std::string raw_type;  // "uint8"
    std::string range;     // "MIN:MAX" visualization range override
    std::string max_memory;  // "12G", "512MB", "1.5GiB", bytes; empty: the default budget
    bool allow_external_data = false;
    std::optional<int64_t> frame;  // --frame: the volume of a 4D NIfTI file
    std::string spacing;           // --spacing X,Y,Z for .raw files (mm)
};
void add_volume_args(CLI::App& cmd, VolumeArgs& a, bool required = true);
// Loads the volume (with a progress line on a terminal) and applies --range.
Volume load_volume(const VolumeArgs& a);

// Parses a byte count: a number with an optional unit k, M, G, T (powers of 1000) or KiB, MiB,
// GiB, TiB (powers of 1024), "B" optional: "12G", "512MB", "1.5GiB", "100000". Throws
// lacuna::Error(where, "size", ...).
uint64_t parse_bytes(const std::string& s, const std::string& where);

// Parses "AxBxC" into dims; throws lacuna::Error(where, "dims", ...).
Vec3i parse_dims(const std::string& s, const std::string& where);
// Parses "X,Y,Z" (positive, finite, mm) into a spacing; throws lacuna::Error(where, "spacing", ...).
Vec3d parse_spacing(const std::string& s, const std::string& where);

// Fails early (before any work) if `path` cannot be created: its folder must exist and be
// writable, and it must end with `ext`. Throws lacuna::Error(path, "output", ...).
void check_output_path(const std::string& path, const std::string& ext);

// A named anatomical view (Slicer's): anterior, posterior, left, right, superior, inferior, as
// orbit azimuth and elevation (lacuna/camera.h OrbitParams). Throws lacuna::Error with the list.
void parse_view(const std::string& name, float& azimuth, float& elevation);
inline constexpr const char* kViewHelp =
    "Anatomical view: anterior, posterior, left, right, superior or inferior (sets --azimuth and "
    "--elevation; world is patient RAS)";

// A progress line on stderr, shown only when stderr is a terminal.
class Progress {
public:
    explicit Progress(std::string what);
    void update(double fraction);
    void done();
    ~Progress();

private:
    std::string m_what;
    bool m_tty;
    bool m_done = false;
    std::chrono::steady_clock::time_point m_start;
};

void register_info(CLI::App& app);
void register_render(CLI::App& app);
void register_generate(CLI::App& app);
void register_bench(CLI::App& app);
void register_partition(CLI::App& app);
void register_serve(CLI::App& app);

}  // namespace lacuna::cli
