// The distributed flags of `lacuna render` outside mpirun: checked like every flag, and without
// an MPI launcher they change nothing (the frame is the single-process frame, byte for byte).
#include <gtest/gtest.h>

#include "apps/cli_run.h"

namespace lacuna::test {
namespace {

namespace fs = std::filesystem;

TEST(CliMpiFlags, OutsideMpirunTheFrameIsUnchanged) {
    const fs::path dir = cli_temp_dir("mpiflags");
    const std::string vol = (dir / "v.nrrd").string();
    ASSERT_EQ(run_cli("generate sphere --dims 24x20x28 --quiet --out " + vol, dir).code, 0);
    const std::string frame = "render " + vol + " --tf ct-soft-tissue --size 32 --quiet";
    const CliResult a = run_cli(frame + " --out " + (dir / "a.png").string(), dir);
    ASSERT_EQ(a.code, 0) << a.err;
    const CliResult b =
        run_cli(frame + " --balance visible --composite binary-swap --rank-times --out " +
                    (dir / "b.png").string(),
                dir);
    ASSERT_EQ(b.code, 0) << b.err;
    EXPECT_EQ(slurp_file(dir / "a.png"), slurp_file(dir / "b.png"));
    EXPECT_EQ(b.out.find("ranks"), std::string::npos) << b.out;
}

TEST(CliMpiFlags, UnknownNamesAreOneLineErrors) {
    const fs::path dir = cli_temp_dir("mpiflags");
    const std::string vol = (dir / "w.nrrd").string();
    ASSERT_EQ(run_cli("generate sphere --dims 8x8x8 --quiet --out " + vol, dir).code, 0);
    expect_one_line_error(run_cli("render " + vol + " --tf ct-bone --composite radix-2 --out " +
                                      (dir / "x.png").string(),
                                  dir),
                          "--composite");
    expect_one_line_error(
        run_cli("render " + vol + " --tf ct-bone --balance cells --out " + (dir / "x.png").string(),
                dir),
        "--balance");
}

}  // namespace
}  // namespace lacuna::test
