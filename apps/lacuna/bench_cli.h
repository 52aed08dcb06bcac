// Pieces shared by the `lacuna bench ...` commands (cmd_bench*.cpp): comma lists, the exact
// command line for the report header, the progress log and the output folder.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace lacuna::cli {

// "a,,b," -> {"a", "b"}: the non-empty comma-separated items.
std::vector<std::string> split_list(const std::string& s);

// One item of a comma-separated integer list (at most 6 digits, no sign). Throws
// lacuna::Error(where, "list", ...) naming the whole `list` when it is not.
int parse_count(const std::string& item, const std::string& where, const std::string& list);

// How command_line() joins the arguments.
enum class ArgQuoting {
    QuoteSpaces,  // arguments with blanks or quotes are wrapped in '...' (faludi, kdtree)
    Plain,        // arguments joined with single spaces as they are (li)
};

// The exact command line, from /proc/self/cmdline; `fallback` where that cannot be read.
std::string command_line(const std::string& fallback, ArgQuoting quoting = ArgQuoting::QuoteSpaces);

// Prints one progress line on stdout and flushes it (the benchmarks' log callback).
void log_line(const std::string& s);

// Creates the folder `out_dir` (and its parents) if needed; throws
// lacuna::Error(out_dir, "--out-dir", ...) if it cannot.
std::filesystem::path create_out_dir(const std::string& out_dir);

}  // namespace lacuna::cli
