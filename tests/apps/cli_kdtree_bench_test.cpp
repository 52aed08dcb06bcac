// `lacuna bench kdtree` end to end (a --quick run: tiny volumes, one view).
#include "apps/cli_run.h"

namespace lacuna::test {
namespace {

TEST(CliBenchKdtree, QuickRunWritesTheReportAndIsExact) {
    const auto dir = cli_temp_dir("kdbench");
    const CliResult r =
        run_cli("bench kdtree --quick --threads 2 --out-dir " + (dir / "out").string(), dir);
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    const std::string md = slurp_file(dir / "out" / "kdtree.md");
    const std::string csv = slurp_file(dir / "out" / "kdtree.csv");
    for (const char* s : {"## Preprocessing", "step 1 classify", "| all leaves |", "| M=32 |",
                          "ch2bet 24³", "tree 40³", "holes kept", "## Targets", "Machine:"})
        EXPECT_NE(md.find(s), std::string::npos) << s << "\n" << md;
    EXPECT_EQ(md.find("**NO**"), std::string::npos) << md;
    // 2 datasets x 2 sizes x 7 lists + header.
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 29) << csv;
    EXPECT_NE(r.out.find("exact yes"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("exact NO"), std::string::npos) << r.out;
}

TEST(CliBenchKdtree, BadOptionsAreOneLineErrors) {
    const auto dir = cli_temp_dir("kdbench-bad");
    expect_one_line_error(run_cli("bench kdtree --quick --max-boxes 0,4", dir), "--max-boxes");
    expect_one_line_error(run_cli("bench kdtree --quick --datasets brain", dir),
                          "--datasets: dataset: unknown 'brain'");
    expect_one_line_error(run_cli("bench kdtree --quick --sizes 2", dir), "--sizes");
    expect_one_line_error(run_cli("bench kdtree --quick --min-gain 3", dir), "--min-gain");
}

}  // namespace
}  // namespace lacuna::test
