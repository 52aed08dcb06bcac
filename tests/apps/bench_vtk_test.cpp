// `lacuna bench vtk` without VTK: bad flags and a missing python3-vtk9 are one-line errors with
// exit code 2 (the benchmark itself needs VTK and xvfb: docs/benchmarks.md, "VTK peer").
#include <cstdlib>

#include "apps/cli_run.h"

namespace lacuna::test {
namespace {

TEST(CliBenchVtk, BadOptionsAreOneLineErrors) {
    const auto dir = cli_temp_dir("vtkbench-bad");
    const std::string out = " --out-dir " + (dir / "out").string();
    expect_one_line_error(run_cli("bench vtk --rounds 0" + out, dir), "--rounds");
    expect_one_line_error(run_cli("bench vtk --frames 0" + out, dir), "--frames");
    expect_one_line_error(run_cli("bench vtk --shading pbr" + out, dir),
                          "--shading: model: expected none or phong, got 'pbr'");
    expect_one_line_error(run_cli("bench vtk --sizes 512,x" + out, dir), "--sizes");
    expect_one_line_error(run_cli("bench vtk --sizes 8" + out, dir), "--sizes");
    expect_one_line_error(run_cli("bench vtk --step 0" + out, dir), "--step");
    expect_one_line_error(run_cli("bench vtk --threads 0" + out, dir), "--threads");
}

TEST(CliBenchVtk, MissingVtkNamesTheInstallStep) {
    const auto dir = cli_temp_dir("vtkbench-novtk");
    ::setenv("LACUNA_PYTHON", "/nonexistent/python3", 1);
    const CliResult r = run_cli("bench vtk --quick --out-dir " + (dir / "out").string(), dir);
    ::unsetenv("LACUNA_PYTHON");
    expect_one_line_error(r, "python3-vtk9");
    EXPECT_NE(r.err.find("scripts/install-deps --bench"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace lacuna::test
