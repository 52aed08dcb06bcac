#include "bench/report.h"

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/parallel.h"
#include "lacuna/error.h"

namespace lacuna::bench {

namespace {

std::string trim(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
    size_t b = 0;
    while (b < s.size() && (s[b] == ' ' || s[b] == '\t')) ++b;
    return s.substr(b);
}

// First line of a shell command's output ("" on failure).
std::string command_output(const char* cmd) {
    FILE* p = popen(cmd, "r");
    if (!p) return "";
    char buf[256];
    std::string out;
    if (std::fgets(buf, sizeof buf, p)) out = buf;
    const int rc = pclose(p);
    return rc == 0 ? trim(out) : "";
}

std::string dims_text(const DatasetResult& d) {
    return std::to_string(d.dims.x) + "×" + std::to_string(d.dims.y) + "×" +
           std::to_string(d.dims.z) + " " + lacuna::to_string(d.type);
}

std::string mode_label(RowMode m, const std::string& unit) {
    return unit.empty() ? to_string(m) : to_string(m) + " [" + unit + "]";
}

// A ratio with enough digits to be read: 0.35, 3.5, 35, 35000.
std::string ratio_text(double r) {
    return fmt(r < 10 ? "%.2g×" : "%.0f×", r);
}

// Header of a table whose columns are the structures.
std::string structure_header(const std::string& first, const std::string& second,
                             const std::vector<AccelKind>& kinds, const std::string& extra = {}) {
    std::string h = "| " + first + " | " + second + " |", rule = "|---|---|";
    for (AccelKind k : kinds) h += " " + to_string(k) + " |", rule += "---:|";
    if (!extra.empty()) h += " " + extra + " |", rule += "---:|";
    return h + "\n" + rule + "\n";
}

// The first column of row r of a dataset block: name on the first line, dims and TF next.
std::string dataset_cell(const DatasetResult& d, size_t r) {
    if (r == 0) return "**" + d.name + "**";
    if (r == 1) return dims_text(d) + ", " + d.tf_name;
    return "";
}

// A Table-1-shaped matrix: per dataset, one line per row, one column per structure.
template <class CellFn>
std::string matrix(const FaludiReport& rep, const std::vector<AccelKind>& kinds,
                   const std::string& unit, CellFn&& cell, bool generation_row) {
    std::string out = structure_header("Dataset", "", kinds);
    for (const DatasetResult& d : rep.datasets) {
        size_t line = 0;
        for (const RowResult& r : d.rows) {
            out += "| " + dataset_cell(d, line++) + " | " + mode_label(r.mode, unit) + " |";
            for (AccelKind k : kinds) {
                const CellResult* c = r.find(k);
                out += " " + (c ? cell(r, *c) : std::string("–")) + " |";
            }
            out += "\n";
        }
        if (generation_row) {
            out += "| " + dataset_cell(d, line++) + " | Generation [ms] |";
            for (AccelKind k : kinds) {
                const StructureResult* s = d.find(k);
                out += " " +
                       (k == AccelKind::None || !s ? std::string("–")
                                                   : fmt("%.1f", s->generation_ms)) +
                       " |";
            }
            out += "\n";
        }
        while (line < 2) {  // keep the dims line when a dataset has a single row
            out += "| " + dataset_cell(d, line++) + " | |";
            for (size_t i = 0; i < kinds.size(); ++i) out += " |";
            out += "\n";
        }
    }
    return out;
}

std::vector<AccelKind> report_kinds(const FaludiReport& rep) {
    return bench_columns(rep.options.accels);
}

std::string accel_options_text(const AccelOptions& a) {
    return "octrees: leaf " + std::to_string(a.leaf_cells) + "³ cells, bitfield " +
           std::to_string(a.bitfield_bits) + " bits, initial level " +
           (a.initial_level < 0 ? std::string("root") : std::to_string(a.initial_level)) + ", " +
           (a.bidirectional ? "bidirectional" : "top-down") +
           " traversal; distance maps: " + std::to_string(a.distance_block) +
           "³ cells per map voxel";
}

}  // namespace

std::string current_load() {
    std::ifstream f("/proc/loadavg");
    std::string a, b, c;
    if (!(f >> a >> b >> c)) return "";
    return a + " " + b + " " + c;
}

RunInfo collect_run_info(const std::string& command_line) {
    RunInfo info;
    info.command_line = command_line;
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M %Z", std::localtime(&now));
    info.date = buf;
    std::ifstream cpu("/proc/cpuinfo");
    for (std::string line; std::getline(cpu, line);)
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) info.cpu = trim(line.substr(colon + 1));
            break;
        }
    if (info.cpu.empty()) info.cpu = "unknown CPU";
    info.cores = resolve_threads(0);
    info.commit = command_output("git rev-parse --short HEAD 2>/dev/null");
    if (!info.commit.empty() &&
        !command_output("git status --porcelain --untracked-files=no 2>/dev/null | head -1")
             .empty())
        info.commit += " (with uncommitted changes)";
    info.load_start = current_load();
    return info;
}

std::string run_info_markdown(const RunInfo& info) {
    std::string out;
    out += "- Command: `" + info.command_line + "`\n";
    out += "- Date: " + info.date + "\n";
    out += "- Machine: " + info.cpu + ", " + std::to_string(info.cores) + " hardware threads\n";
    if (!info.load_start.empty())
        out += "- Load average (1/5/15 min) at start: " + info.load_start +
               (info.load_end.empty() ? "" : "; at end: " + info.load_end) + "\n";
    out += "- lacuna commit: " +
           (info.commit.empty() ? std::string("unknown (not run inside the repository)")
                                : info.commit) +
           "\n";
    return out;
}

std::string faludi_markdown(const FaludiReport& rep, const RunInfo& info) {
    const FaludiOptions& o = rep.options;
    const std::vector<AccelKind> kinds = report_kinds(rep);
    std::string out = "# lacuna bench faludi: Table 1 of Faludi et al. (2021) on our data\n\n";
    out += run_info_markdown(info);
    out += "- Settings: " + std::to_string(o.orbit.size) + "×" + std::to_string(o.orbit.size) +
           " pixels, " + std::to_string(o.orbit.views) + " views (azimuth 360°·i/" +
           std::to_string(o.orbit.views) + ", elevation " + fmt("%g", o.orbit.elevation_deg) +
           "°, perspective, default framing), step " + fmt("%g", o.step) + " voxel, threads " +
           (o.threads > 0 ? std::to_string(o.threads) : "all") +
           ". \"Marching only\" = no early ray termination; \"+ Early exit\" = ERT at " +
           fmt("%g", o.ert) + ".\n";
    out += "- Structures: " + accel_options_text(o.accel) + "\n\n";

    out += "## Mean frame time [ms] (the paper's Table 1 layout)\n\n";
    out += matrix(
        rep, kinds, "ms",
        [](const RowResult&, const CellResult& c) { return fmt("%.1f", c.frame_ms.mean); }, true);
    out += "\nGeneration = building the structure and applying the first TF (wall time).\n\n";

    out += "## Slowest frame: p99 frame time [ms]\n\n";
    out +=
        "Nearest-rank 99th percentile over the orbit (with fewer than 100 views: the slowest "
        "view).\n\n";
    out += matrix(
        rep, kinds, "ms",
        [](const RowResult&, const CellResult& c) { return fmt("%.1f", c.frame_ms.p99); }, false);

    out += "\n## Samples per ray\n\n";
    out += matrix(
        rep, kinds, "",
        [](const RowResult&, const CellResult& c) { return fmt("%.1f", c.samples_per_ray()); },
        false);

    out += "\n## Speedup over none, and the ideal speedup\n\n";
    out +=
        "Each cell: frame-time speedup over `none` in the same run (sample reduction in brackets). "
        "Ideal = samples of `none` / samples in cells that can be visible under the TF "
        "(src/render/sample_analysis.h). \"% of ideal (time)\" = bitfield's frame-time speedup / "
        "ideal; "
        "\"% of ideal (samples)\" = bitfield's sample reduction / ideal (how close its skipping "
        "comes to "
        "skipping every invisible cell, whatever a skip costs).\n\n";
    {
        std::vector<AccelKind> rest(kinds.begin() + 1, kinds.end());
        std::string h = "| Dataset | Row | ideal |", rule = "|---|---|---:|";
        for (AccelKind k : rest) h += " " + to_string(k) + " |", rule += "---:|";
        h += " bitfield % of ideal (time) | bitfield % of ideal (samples) |", rule += "---:|---:|";
        out += h + "\n" + rule + "\n";
        for (const DatasetResult& d : rep.datasets)
            for (const RowResult& r : d.rows) {
                out +=
                    "| " + d.name + " | " + to_string(r.mode) + " | " +
                    (r.ideal_speedup() > 0 ? fmt("%.2f×", r.ideal_speedup()) : std::string("–")) +
                    " |";
                for (AccelKind k : rest) {
                    const CellResult* c = r.find(k);
                    out += " " +
                           (c ? fmt("%.2f×", c->speedup) + " (" +
                                    fmt("%.2f×", c->sample_reduction) + ")"
                              : std::string("–")) +
                           " |";
                }
                const CellResult* bf = r.find(AccelKind::Bitfield);
                const bool has = r.ideal_speedup() > 0 && bf;
                out += " " +
                       (has ? fmt("%.0f%%", 100 * r.share_of_ideal(AccelKind::Bitfield))
                            : std::string("–")) +
                       " | " +
                       (has ? fmt("%.0f%%", 100 * bf->sample_reduction / r.ideal_speedup())
                            : std::string("–")) +
                       " |\n";
            }
    }

    out += "\n## Exactness: view 0 byte-identical to none\n\n";
    out += matrix(
        rep, kinds, "",
        [](const RowResult&, const CellResult& c) {
            return std::string(c.exact ? "yes" : "**NO**");
        },
        false);
    const auto failures = rep.exactness_failures();
    out += failures.empty()
               ? "\nEvery structure's view 0 equals none's, byte for byte.\n"
               : "\n**" + std::to_string(failures.size()) + " cell(s) differ from none: a bug.**\n";

    out += "\n## Structures: generation, memory, TF change\n\n";
    out +=
        "Build = the TF-independent part (AccelStats::build_seconds; for TF-dependent structures "
        "the last rebuild). TF change = median of " +
        std::to_string(o.tf_repeats) +
        " TF changes (AccelStats::tf_update_seconds). Refine = the " +
        "finer per-TF level computed after the change (Accel::refine; " +
        (o.refine ? "the frames use it" : "not run: --no-refine") + ").\n\n";
    out +=
        "| Dataset | Structure | Generation [ms] | Build [ms] | TF change [ms] | TF change ÷ "
        "bitfield's | Refine [ms] | Memory [MiB] | Nodes |\n";
    out += "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const DatasetResult& d : rep.datasets) {
        const StructureResult* bf = d.find(AccelKind::Bitfield);
        for (const StructureResult& s : d.structures) {
            if (s.kind == AccelKind::None) continue;
            const std::string ratio = bf && bf->tf_change_ms > 0 && s.kind != AccelKind::Bitfield
                                          ? ratio_text(s.tf_change_ms / bf->tf_change_ms)
                                          : std::string("–");
            out += "| " + d.name + " | " + to_string(s.kind) + " | " +
                   fmt("%.1f", s.generation_ms) + " | " + fmt("%.1f", s.build_ms) + " | " +
                   fmt("%.4f", s.tf_change_ms) + " | " + ratio + " | " + fmt("%.1f", s.refine_ms) +
                   " | " + fmt("%.2f", double(s.bytes) / (1 << 20)) + " | " +
                   std::to_string(s.nodes) + " |\n";
        }
    }

    out +=
        "\n## Datasets\n\n| Dataset | Source | Dims | Spacing [mm] | Visible cells "
        "|\n|---|---|---|---|---:|\n";
    for (const DatasetResult& d : rep.datasets)
        out += "| " + d.name + " | " + d.description + " | " + dims_text(d) + " | " +
               fmt("%g", d.spacing.x) + "×" + fmt("%g", d.spacing.y) + "×" +
               fmt("%g", d.spacing.z) + " | " + fmt("%.2f%%", 100 * d.visible_cell_fraction) +
               " |\n";

    out += "\n## Targets\n\n| Target | Measured | Status |\n|---|---|---|\n";
    for (const TargetCheck& t : check_targets(rep))
        out += "| " + t.target + " | " + t.measured + " | " + to_string(t.status) + " |\n";
    return out;
}

std::string faludi_csv(const FaludiReport& rep) {
    std::ostringstream out;
    out << "dataset,description,dims,voxel_type,tf,row,ert,structure,size,views,mean_ms,p99_ms,min_"
           "ms,max_ms,"
           "samples,rays,samples_per_ray,speedup,sample_reduction,ideal_samples,ideal_speedup,"
           "share_of_ideal,exact,generation_ms,build_ms,tf_change_ms,bytes,nodes\n";
    const FaludiOptions& o = rep.options;
    for (const DatasetResult& d : rep.datasets)
        for (const RowResult& r : d.rows)
            for (const CellResult& c : r.cells) {
                const StructureResult* s = d.find(c.kind);
                char buf[1024];
                std::snprintf(
                    buf, sizeof buf,
                    "%s,\"%s\",%dx%dx%d,%s,%s,%s,%g,%s,%d,%d,%.4f,%.4f,%.4f,%.4f,%llu,%llu,%.4f,"
                    "%.4f,%.4f,%llu,%.4f,%.4f,%s,%.4f,%.4f,%.6f,%zu,%zu\n",
                    d.name.c_str(), d.description.c_str(), d.dims.x, d.dims.y, d.dims.z,
                    lacuna::to_string(d.type).c_str(), d.tf_name.c_str(), csv_name(r.mode).c_str(),
                    r.ert, to_string(c.kind).c_str(), o.orbit.size, o.orbit.views, c.frame_ms.mean,
                    c.frame_ms.p99, c.frame_ms.min, c.frame_ms.max, (unsigned long long)c.samples,
                    (unsigned long long)c.rays, c.samples_per_ray(), c.speedup, c.sample_reduction,
                    (unsigned long long)r.ideal_samples, r.ideal_speedup(),
                    c.kind == AccelKind::None ? 0. : r.share_of_ideal(c.kind),
                    c.exact ? "yes" : "no", s ? s->generation_ms : 0., s ? s->build_ms : 0.,
                    s ? s->tf_change_ms : 0., s ? s->bytes : size_t(0), s ? s->nodes : size_t(0));
                out << buf;
            }
    return out.str();
}

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

void write_text_file(const std::string& path, const std::string& text) {
    const std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) throw Error(path, "output", "cannot create the file");
        f << text;
        if (!f.flush()) throw Error(path, "output", "write failed");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw Error(path, "output", "cannot rename into place: " + ec.message());
}

}  // namespace lacuna::bench
