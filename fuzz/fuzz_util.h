// Shared by the harnesses: what a finding is. A harness feeds its input to one parser; a
// lacuna::Error is the expected answer to a malformed input (the CLI prints it and exits 2).
// Anything else is a finding: another exception escaping (guarded() lets it reach libFuzzer, which
// reports it as a crash), a broken invariant (fuzz_check aborts with the operands), or
// whatever ASan/UBSan catch underneath.
#pragma once
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "lacuna/error.h"

namespace lacuna::fuzz {

inline void fuzz_check(bool ok, const char* what, const std::string& detail = {}) {
    if (ok) return;
    std::fprintf(stderr, "fuzz invariant broken: %s %s\n", what, detail.c_str());
    std::abort();
}

// Writes `bytes` to LACUNA_FUZZ_TMP/<name> (for APIs that take a path); returns the path. The
// name carries the process id so parallel jobs (-jobs=N) do not share files.
inline std::string scratch_file(std::string_view bytes, const std::string& name) {
    const std::string path =
        std::string(LACUNA_FUZZ_TMP) + "/" + std::to_string(getpid()) + "-" + name;
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

// The body of LLVMFuzzerTestOneInput: runs f, swallows lacuna::Error only (anything else
// escapes to libFuzzer, which reports it).
template <class F>
int guarded(F&& f) {
    try {
        f();
    } catch (const Error&) {
    }
    return 0;
}

}  // namespace lacuna::fuzz
