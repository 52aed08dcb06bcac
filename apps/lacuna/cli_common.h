// Shared pieces of the lacuna CLI: the only place strings become typed options (STYLE.md 3).
#pragma once
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

#include "lacuna/camera.h"
#include "lacuna/io.h"
#include "lacuna/volume.h"

namespace lacuna::cli {

// Options shared by every command that loads a volume.
struct VolumeArgs {
    std::string path;
    std::string raw_dims;    // "301x370x316"
    std::string raw_type;    // "uint8"
    std::string range;       // "MIN:MAX" visualization range override
    std::string max_memory;  // "12G", "512MB", "1.5GiB", bytes; empty: the default budget
    bool allow_external_data = false;
    std::optional<int64_t> frame;           // --frame: the volume of a 4D NIfTI file
    std::string spacing;                    // --spacing X,Y,Z for .raw files (mm)
    std::string rgb_opacity = "luminance";  // --rgb-opacity: RGB files' opacity scalar
    // Typed values a session file gives (render --session), used instead of the strings above.
    std::optional<RawSpec> raw_spec;
    std::optional<ValueRange> range_value;
};
void add_volume_args(CLI::App& cmd, VolumeArgs& a, bool required = true);
// Loads the volume (with a progress line on a terminal) and applies --range.
Volume load_volume(const VolumeArgs& a);

// Parses "MIN:MAX" (--range); throws lacuna::Error("--range", "range", ...).
ValueRange parse_range(const std::string& s);
// The raw layout --dims/--type/--spacing give (nullopt: none given; the name may still give one).
std::optional<RawSpec> raw_spec_of(const VolumeArgs& a);

// Parses a byte count: a number with an optional unit k, M, G, T (powers of 1000) or KiB, MiB,
// GiB, TiB (powers of 1024), "B" optional: "12G", "512MB", "1.5GiB", "100000". Throws
// lacuna::Error(where, "size", ...).
uint64_t parse_bytes(const std::string& s, const std::string& where);

// Parses "AxBxC" into dims; throws lacuna::Error(where, "dims", ...).
Vec3i parse_dims(const std::string& s, const std::string& where);
// Parses "X,Y,Z" (positive, finite, mm) into a spacing; throws lacuna::Error(where, "spacing",
// ...).
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

// Progress on stderr (docs/cli.md, "Progress"), for three audiences:
//   - a person at a terminal (stderr is a tty): one line rewritten in place with '\r', either a
//     fraction ("loading head.nii.gz ... 40%") or items done of a total with the elapsed time and
//     the time left ("render: 12/36 frames, 1.4 s, ETA 2.8 s"), at most ten redraws a second;
//   - a script or a log (not a tty): nothing while the work runs, and for a command's summary one
//     line when it has succeeded ("render: 36 frames in 4.20 s (116.7 ms/frame)");
//   - --quiet: nothing at all. Errors are not progress: they are printed whatever --quiet says.
// A Progress abandoned by an exception prints no summary (the error line is the last word) and
// ends its terminal line, so the error starts a line of its own.
void set_quiet(bool quiet);
bool quiet();

class Progress {
  public:
    // A step measured by a fraction (loading a file, building a structure): the terminal only.
    explicit Progress(std::string what);
    // A command's summary over `total` items called `unit` (singular: "frame"); total 0 counts
    // nothing ("generate: done in 1.30 s"). done() prints the summary, on a terminal or not.
    Progress(std::string what, int64_t total, std::string unit);
    void update(double fraction);
    void step(int64_t items_done);  // items finished so far, of the total
    void done();
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

  private:
    void draw(const std::string& line, bool force);
    std::string m_what, m_unit;
    int64_t m_total = -1;  // -1: a fraction, no summary
    int64_t m_items = 0;
    bool m_tty;
    bool m_done = false;
    bool m_drawn = false;  // a terminal line is open (no newline yet)
    std::chrono::steady_clock::time_point m_start, m_last_draw;
};

// Runs a command's work `f` and then prints its summary ("bench li: done in 12.40 s"; stdout is
// flushed first, so a log reads in order).
template <class F>
void with_summary(const std::string& what, F&& f) {
    Progress summary(what, 0, "");
    f();
    std::fflush(stdout);
    summary.done();
}

void register_info(CLI::App& app);
void register_render(CLI::App& app);
void register_generate(CLI::App& app);
void register_bench(CLI::App& app);
void register_partition(CLI::App& app);
void register_serve(CLI::App& app);

}  // namespace lacuna::cli
