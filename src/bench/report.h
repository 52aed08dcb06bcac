// What `lacuna bench` writes: the run's context (machine, date, commit, command), the Table 1
// markdown and the CSV with every number.
#pragma once
#include <string>

#include "bench/faludi.h"

namespace lacuna::bench {

struct RunInfo {
    std::string command_line;  // exactly as typed (the apps/ layer joins argv)
    std::string date;          // local time, "2024-05-01 12:00 CEST"
    std::string cpu;           // model name from /proc/cpuinfo
    int cores = 0;             // hardware threads
    std::string commit;        // `git rev-parse --short HEAD` when run inside the repo, else ""
    std::string load_start;    // /proc/loadavg (1, 5, 15 min) when the run started
    std::string load_end;      // ... and when it ended (fill with current_load())
};
// Collects everything but load_end.
RunInfo collect_run_info(const std::string& command_line);
// The 1, 5 and 15 minute load averages, "1.87 2.25 2.09" ("" when unavailable).
std::string current_load();
// The context block at the top of every markdown report.
std::string run_info_markdown(const RunInfo& info);

// The paper's Table 1 layout (mean frame times) followed by p99, samples per ray, speedups with
// the ideal, exactness, per-structure generation / memory / TF change, and the targets.
std::string faludi_markdown(const FaludiReport& report, const RunInfo& info);
// One line per dataset x row x structure, every number (header in the first line).
std::string faludi_csv(const FaludiReport& report);

// One number formatted with a printf format of one double conversion ("%.2f", "%.1f%%"); the
// result is cut at 63 characters. Every bench report formats its numbers through this.
std::string fmt(const char* format, double v);

// Writes text atomically (temporary file + rename). Throws lacuna::Error(path, "output", ...).
void write_text_file(const std::string& path, const std::string& text);

}  // namespace lacuna::bench
