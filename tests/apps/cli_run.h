// Running the lacuna CLI from tests: exit code, stdout and stderr of one command.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lacuna::test {

struct CliResult {
    int code = -1;
    std::string out, err;
};

inline std::string slurp_file(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// A fresh folder per test binary run, named `tag`.
inline std::filesystem::path cli_temp_dir(const std::string& tag) {
    std::filesystem::path d = std::filesystem::temp_directory_path() /
                              ("lacuna-" + tag + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
}

// One shell command line (its output captured in files of `dir`).
inline CliResult run_command(const std::string& command, const std::filesystem::path& dir) {
    const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string cmd = command + " >" + out.string() + " 2>" + err.string() + " </dev/null";
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp_file(out);
    r.err = slurp_file(err);
    return r;
}

inline CliResult run_cli(const std::string& args, const std::filesystem::path& dir) {
    return run_command(std::string(LACUNA_CLI_PATH) + " " + args, dir);
}

// Exit code 2 and exactly one line on stderr that contains `needle`.
inline void expect_one_line_error(const CliResult& r, const std::string& needle) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
}

}  // namespace lacuna::test
