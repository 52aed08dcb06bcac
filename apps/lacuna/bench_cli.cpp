#include "bench_cli.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

#include "lacuna/error.h"

namespace lacuna::cli {

std::vector<std::string> split_list(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

int parse_count(const std::string& item, const std::string& where, const std::string& list) {
    if (item.empty() || item.size() > 6 ||
        item.find_first_not_of("0123456789") != std::string::npos)
        throw Error(where, "list", "expected comma-separated integers, got '" + list + "'");
    return std::stoi(item);
}

std::string command_line(const std::string& fallback, ArgQuoting quoting) {
    std::ifstream f("/proc/self/cmdline", std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::string out;
    std::stringstream in(all);
    for (std::string arg; std::getline(in, arg, '\0');) {
        if (!out.empty()) out += ' ';
        const bool quote =
            quoting == ArgQuoting::QuoteSpaces && arg.find_first_of(" \t'\"") != std::string::npos;
        out += quote ? "'" + arg + "'" : arg;
    }
    return out.empty() ? fallback : out;
}

void log_line(const std::string& s) {
    std::printf("%s\n", s.c_str());
    std::fflush(stdout);
}

std::filesystem::path create_out_dir(const std::string& out_dir) {
    const std::filesystem::path dir(out_dir);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir))
        throw Error(out_dir, "--out-dir", "cannot create the folder");
    return dir;
}

}  // namespace lacuna::cli
