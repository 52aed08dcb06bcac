// The smoke version of bench/mutate_campaign.py (docs/reliability.md, "Readers"): 42 malformed
// inputs, three from each base volume, each run through `lacuna info` and `lacuna render`.
// Every run must exit 0 or exit 2 with one line, write nothing on failure and leave its input
// unchanged; the script checks that and exits 1 on any violation. The full run (5,000 inputs)
// is a benchmark, not a test.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace {

TEST(MutationCampaign, SmokeRunHasNoViolations) {
    const std::string cmd = std::string("/usr/bin/python3 ") + LACUNA_SOURCE_DIR +
                            "/bench/mutate_campaign.py --lacuna " + LACUNA_CLI_PATH +
                            " --count 42 --jobs 2 --seed 7 --smoke 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[4096];
    while (size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = ::pclose(p);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("mutation campaign: 42 inputs, 84 runs"), std::string::npos) << out;
    EXPECT_NE(out.find(" 0 violations"), std::string::npos) << out;
}

}  // namespace
