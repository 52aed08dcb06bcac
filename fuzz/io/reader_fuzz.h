// Shared by the volume-reader harnesses (fuzz/io/): what a finding is, and scratch files.
//
// A harness writes its input as one or more files in a scratch folder of its own (per process,
// so -jobs=N does not share files), then calls read_volume. lacuna::Error is the expected answer
// to a malformed input; anything else escapes to libFuzzer, which reports it, as it reports
// what ASan/UBSan catch underneath. The budget is 256 MB so that a header claiming a huge volume
// fails the budget check, while one claiming a few MB is allocated and read.
#pragma once
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"

#ifndef LACUNA_FUZZ_TMP
#define LACUNA_FUZZ_TMP "/tmp"
#endif

// LeakSanitizer: ITK 5.2's NrrdImageIO throws out of ReadImageInformation without freeing
// NrrdIO's header (nrrdNew, biffGet), a few kB per rejected NRRD header: ITK's leak, not
// ours, recorded in docs/reliability.md. Suppressed by library, so a leak in our code still
// stops the run. (This header is included by exactly one file per harness.)
extern "C" const char* __lsan_default_suppressions() {
    return "leak:libITKNrrdIO\n";
}

namespace lacuna::fuzz_io {

// A fresh, empty folder LACUNA_FUZZ_TMP/<harness>-<pid>/ (emptied on every call).
inline std::string scratch_dir(const std::string& harness) {
    namespace fs = std::filesystem;
    const fs::path d = fs::path(LACUNA_FUZZ_TMP) / (harness + "-" + std::to_string(::getpid()));
    std::error_code ec;
    fs::remove_all(d, ec);
    fs::create_directories(d, ec);
    return d.string();
}

inline std::string put(const std::string& dir, const std::string& name, std::string_view bytes) {
    const std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

inline ReadOptions fuzz_options() {
    ReadOptions o;
    o.max_memory.bytes = uint64_t(256) << 20;
    return o;
}

// Reads `path`; a lacuna::Error is fine, its message must be one line naming the input.
inline void read_expecting_errors(const std::string& path, const ReadOptions& o = fuzz_options()) {
    try {
        const Volume v = read_volume(path, o);
        if (!v.data()) std::abort();
        // A volume read has a world the renderers' float can hold (check_geometry's rules):
        // finite float bounds, an orientation code.
        const Box3f b = world_bounds(v);
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]) || !(b.lo[a] <= b.hi[a])) {
                std::fprintf(stderr, "fuzz: world bounds not finite on axis %d: %g .. %g\n", a,
                             double(b.lo[a]), double(b.hi[a]));
                std::abort();
            }
        if (orientation_code(v).size() != 3) std::abort();
    } catch (const Error& e) {
        const std::string m = e.what();
        if (m.find('\n') != std::string::npos) {
            std::fprintf(stderr, "fuzz: multi-line error: %s\n", m.c_str());
            std::abort();
        }
    }
}

// Splits `data` at the first occurrence of `sep`: {before, after} (after empty if absent).
inline std::pair<std::string_view, std::string_view> split(std::string_view data,
                                                           std::string_view sep) {
    const size_t at = data.find(sep);
    if (at == std::string_view::npos) return {data, {}};
    return {data.substr(0, at), data.substr(at + sep.size())};
}

}  // namespace lacuna::fuzz_io
