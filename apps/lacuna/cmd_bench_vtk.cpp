// `lacuna bench vtk`: the VTK peer (docs/benchmarks.md, "VTK peer"). The same views rendered by
// VTK's vtkFixedPointVolumeRayCastMapper and by `lacuna render`, interleaved in one run. This
// file only checks the flags, finds python3 (with VTK), xvfb-run and bench/vtk_peer.py, and runs
// the script with this binary as its lacuna; the VTK side and the report live in the script.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bench_cli.h"
#include "cli_common.h"
#include "lacuna/error.h"

namespace lacuna::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kInstallHint = "run scripts/install-deps --bench";

struct VtkArgs {
    std::string cases;  // default: every case of the script
    std::string sizes = "512,1024";
    std::string shading = "none,phong";
    int rounds = 3, frames = 3, threads = 2, tree_size = 512;
    float step = 0.5f, azimuth = 20.f, elevation = 15.f;  // the face, slightly from the left
    std::string accel;                                    // empty: lacuna render's default
    std::string out_dir = "out/bench-vtk";
    std::string templates = "/usr/share/mricron/templates";
    bool quick = false;
    bool cases_given = false, sizes_given = false, rounds_given = false, frames_given = false;
};

// Runs argv (argv[0] a path) and returns its exit status; `quiet` sends its output to
// /dev/null. -1 if it could not be started or did not exit normally.
int run_process(const std::vector<std::string>& argv, bool quiet) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = ::fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        if (quiet) {
            const int null = ::open("/dev/null", O_WRONLY);
            if (null >= 0) {
                ::dup2(null, 1);
                ::dup2(null, 2);
            }
        }
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// `name` on PATH (or as given when it contains a '/'); empty when not found.
std::string find_program(const std::string& name) {
    if (name.find('/') != std::string::npos) return ::access(name.c_str(), X_OK) == 0 ? name : "";
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        if (dir.empty()) continue;
        const fs::path p = fs::path(dir) / name;
        if (::access(p.c_str(), X_OK) == 0) return p.string();
    }
    return "";
}

// A python3 that can import VTK's volume rendering: $LACUNA_PYTHON if set, else Debian's
// /usr/bin/python3 (where python3-vtk9 installs), else python3 on PATH.
std::string find_python() {
    std::vector<std::string> candidates;
    if (const char* env = std::getenv("LACUNA_PYTHON"); env && *env)
        candidates = {env};
    else
        candidates = {"/usr/bin/python3", "python3"};
    for (const std::string& c : candidates) {
        const std::string exe = find_program(c);
        if (!exe.empty() &&
            run_process({exe, "-c", "import vtkmodules.vtkRenderingVolume"}, true) == 0)
            return exe;
    }
    return "";
}

// bench/vtk_peer.py: beside the binary (build/lacuna -> bench/), else in the source tree this
// file was compiled from (__FILE__ is absolute under CMake).
std::string find_script() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    std::vector<fs::path> candidates;
    if (!ec) {
        candidates.push_back(exe.parent_path() / "vtk_peer.py");
        candidates.push_back(exe.parent_path().parent_path() / "bench" / "vtk_peer.py");
    }
    candidates.push_back(fs::path(__FILE__).parent_path().parent_path().parent_path() / "bench" /
                         "vtk_peer.py");
    for (const fs::path& p : candidates)
        if (fs::is_regular_file(p, ec)) return p.string();
    return "";
}

void check(const VtkArgs& a) {
    if (a.rounds < 1 || a.rounds > 1000) throw Error("--rounds", "rounds", "expected 1..1000");
    if (a.frames < 1 || a.frames > 1000) throw Error("--frames", "frames", "expected 1..1000");
    if (a.threads < 1 || a.threads > 1024) throw Error("--threads", "threads", "expected 1..1024");
    if (a.tree_size < 2 || a.tree_size > 2048)
        throw Error("--tree-size", "size", "expected 2..2048");
    if (!(a.step > 0.f && a.step <= 64.f)) throw Error("--step", "step", "expected 0 < step <= 64");
    const auto sizes = split_list(a.sizes);
    if (sizes.empty()) throw Error("--sizes", "list", "expected at least one image size");
    for (const std::string& s : sizes) {
        const int n = parse_count(s, "--sizes", a.sizes);
        if (n < 16 || n > 4096) throw Error("--sizes", "image size", "expected 16..4096, got " + s);
    }
    const auto shadings = split_list(a.shading);
    if (shadings.empty()) throw Error("--shading", "list", "expected none and/or phong");
    for (const std::string& s : shadings)
        if (s != "none" && s != "phong")
            throw Error("--shading", "model", "expected none or phong, got '" + s + "'");
}

void run_vtk(VtkArgs& a) {
    if (a.quick) {  // one small case: a smoke run
        if (!a.cases_given) a.cases = "ch2-skin";
        if (!a.sizes_given) a.sizes = "256";
        if (!a.rounds_given) a.rounds = 1;
        if (!a.frames_given) a.frames = 1;
    }
    check(a);
    create_out_dir(a.out_dir);
    const std::string python = find_python();
    if (python.empty())
        throw Error("bench vtk", "python3-vtk9",
                    std::string("no python3 that can import vtk; ") + kInstallHint);
    const std::string xvfb = find_program("xvfb-run");
    if (xvfb.empty())
        throw Error("bench vtk", "xvfb", std::string("xvfb-run not found; ") + kInstallHint);
    const std::string script = find_script();
    if (script.empty())
        throw Error("bench vtk", "bench/vtk_peer.py",
                    "not found beside the binary or in the source tree");
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("bench vtk", "/proc/self/exe", "cannot find this binary");
    // Flags with an empty value (--cases, --accel not given) are left to the script's defaults.
    const std::pair<const char*, std::string> flags[] = {
        {"--lacuna", self.string()},
        {"--cases", a.cases},
        {"--sizes", a.sizes},
        {"--shading", a.shading},
        {"--rounds", std::to_string(a.rounds)},
        {"--frames", std::to_string(a.frames)},
        {"--threads", std::to_string(a.threads)},
        {"--step", std::to_string(a.step)},
        {"--azimuth", std::to_string(a.azimuth)},
        {"--elevation", std::to_string(a.elevation)},
        {"--tree-size", std::to_string(a.tree_size)},
        {"--templates", a.templates},
        {"--out-dir", a.out_dir},
        {"--accel", a.accel},
        {"--command", command_line("lacuna bench vtk")},
    };
    std::vector<std::string> argv = {xvfb, "-a", "-s", "-screen 0 1280x1024x24", python, script};
    for (const auto& [flag, value] : flags)
        if (!value.empty()) argv.insert(argv.end(), {flag, value});
    const int code = run_process(argv, false);
    if (code < 0) throw Error("bench vtk", script, "did not run to completion (killed?)");
    // The script has printed its own one-line error (`lacuna: bench vtk: ...`); keep its code.
    if (code != 0) std::exit(code);
}

}  // namespace

void register_bench_vtk(CLI::App& bench) {
    auto a = std::make_shared<VtkArgs>();
    auto* c = bench.add_subcommand(
        "vtk", "VTK's fixed-point ray caster on the same views, interleaved with lacuna");
    c->add_option("--cases", a->cases,
                  "Comma-separated cases (default all): ch2-skin, ch2better-skin, ch2-sparse, "
                  "ch2bet-skin, tree512-skin");
    c->add_option("--sizes", a->sizes, "Comma-separated image sizes")->capture_default_str();
    c->add_option("--rounds", a->rounds, "Interleaved rounds (medians reported)")
        ->capture_default_str();
    c->add_option("--frames", a->frames, "Timed frames per side, case and round")
        ->capture_default_str();
    c->add_option("--shading", a->shading, "Comma-separated: none, phong")->capture_default_str();
    c->add_option("--out-dir", a->out_dir, "Folder for vtk.md, vtk.csv and the PNG pairs")
        ->capture_default_str();
    c->add_flag("--quick", a->quick, "Smoke run: ch2-skin at 256², 1 round, 1 frame unless given");
    c->add_option("--accel", a->accel, "Passed to lacuna render (default: its own default)");
    c->add_option("--threads", a->threads, "Threads for both renderers")->capture_default_str();
    c->add_option("--step", a->step, "Sample distance in units of the smallest spacing")
        ->capture_default_str();
    c->add_option("--azimuth", a->azimuth, "Orbit azimuth in degrees")->capture_default_str();
    c->add_option("--elevation", a->elevation, "Orbit elevation in degrees")->capture_default_str();
    c->add_option("--tree-size", a->tree_size, "Edge of the generated tree volume")
        ->capture_default_str();
    c->add_option("--templates", a->templates, "Folder of the mricron templates")
        ->capture_default_str();
    c->callback([a, c] {
        a->cases_given = c->count("--cases") > 0;
        a->sizes_given = c->count("--sizes") > 0;
        a->rounds_given = c->count("--rounds") > 0;
        a->frames_given = c->count("--frames") > 0;
        with_summary("bench vtk", [&] { run_vtk(*a); });
    });
}

}  // namespace lacuna::cli
