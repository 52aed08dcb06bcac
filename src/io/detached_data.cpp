#include "io/detached_data.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include "io/io_util.h"
#include "lacuna/error.h"

namespace lacuna::io {

namespace fs = std::filesystem;

namespace {

// True when `p` (canonical) is `dir` (canonical) or lies below it.
bool is_below(const fs::path& p, const fs::path& dir) {
    const fs::path rel = p.lexically_relative(dir);
    return !rel.empty() && *rel.begin() != "..";
}

}  // namespace

void check_data_file(const std::string& header, const std::string& field, const std::string& name,
                     bool allow_external) {
    if (name.empty()) throw Error(header, field, "names no data file");
    fs::path dir = fs::path(header).parent_path();
    if (dir.empty()) dir = ".";
    const fs::path p = fs::path(name).is_absolute() ? fs::path(name) : dir / name;
    const std::string shown = "data file '" + one_line(name, 120) + "'";
    struct stat st {};
    if (::stat(p.c_str(), &st) != 0)
        throw Error(header, field, shown + ": " + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) throw Error(header, field, shown + " is not a regular file");
    if (allow_external) return;
    std::error_code ec1, ec2;
    const fs::path real = fs::canonical(p, ec1), real_dir = fs::canonical(dir, ec2);
    if (ec1 || ec2) throw Error(header, field, shown + ": cannot resolve its path");
    if (!is_below(real, real_dir))
        throw Error(header, field,
                    shown +
                        " is outside the header's folder (allow it with the external-data "
                        "option)");
}

std::vector<std::string> check_nrrd_data_files(const std::string& header, bool allow_external) {
    std::vector<std::string> checked;
    fs::path dir = fs::path(header).parent_path();
    const auto keep = [&](const std::string& name) {
        check_data_file(header, "data file", name, allow_external);
        checked.push_back((fs::path(name).is_absolute() ? fs::path(name) : dir / name).string());
    };
    std::ifstream in(header, std::ios::binary);
    std::string line;
    std::string spec;
    // A NRRD header is a few dozen lines; stop at the blank line that ends it.
    int n = 0;
    for (; n < 10000 && std::getline(in, line); ++n) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) break;
        if (line.rfind("data file:", 0) == 0 || line.rfind("datafile:", 0) == 0) {
            spec = trim(line.substr(line.find(':') + 1));
            if (spec.empty()) throw Error(header, "data file", "names no data file");
        }
    }
    if (spec.empty()) return checked;
    const std::string field = "data file";
    std::istringstream words(spec);
    std::vector<std::string> w;
    for (std::string t; words >> t;) w.push_back(t);
    // trim() keeps form feeds and vertical tabs, which the word split drops.
    if (w.empty()) throw Error(header, field, "names no data file");
    if (w[0] == "LIST") {
        // The names follow the header, one per line.
        int files = 0;
        while (std::getline(in, line) && files <= kMaxDim) {
            const std::string name = trim(line);
            if (name.empty()) continue;
            keep(name);
            ++files;
        }
        if (files == 0) throw Error(header, field, "LIST names no data files");
        return checked;
    }
    if (spec.find('%') != std::string::npos) {
        // "<format> <min> <max> <step> [<subdim>]": the format may hold one %d conversion and
        // nothing else a printf would interpret (a header must never choose the conversions).
        static const std::regex kFormat(R"(^[^%]*%0?[0-9]{0,2}d[^%]*$)");
        constexpr long long kBound = 1000000000;  // keeps hi - lo and int(i) exact
        long long lo = 0, hi = 0, step = 0;
        if (w.size() < 4 || w.size() > 5 || !std::regex_match(w[0], kFormat) ||
            std::sscanf(w[1].c_str(), "%lld", &lo) != 1 ||
            std::sscanf(w[2].c_str(), "%lld", &hi) != 1 ||
            std::sscanf(w[3].c_str(), "%lld", &step) != 1 || step == 0 || lo < -kBound ||
            lo > kBound || hi < -kBound || hi > kBound || (hi - lo) / step < 0 ||
            (hi - lo) / step > kMaxDim)
            throw Error(header, field,
                        "expected '<name with one %d> <min> <max> <step>', got '" +
                            one_line(spec, 120) + "'");
        for (long long i = lo; step > 0 ? i <= hi : i >= hi; i += step) {
            char name[4096];
            std::snprintf(name, sizeof name, w[0].c_str(), int(i));
            keep(name);
        }
        return checked;
    }
    keep(spec);
    return checked;
}

}  // namespace lacuna::io
