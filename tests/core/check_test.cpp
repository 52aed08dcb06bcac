// CHECK and DCHECK (src/core/check.h): a failed CHECK prints where, the condition and both
// operands, and aborts; a passing one does nothing; a DCHECK is evaluated only without NDEBUG.
#include "core/check.h"

#include <gtest/gtest.h>

#include <string>

namespace lacuna {
namespace {

TEST(Check, APassingCheckDoesNothing) {
    int n = 3;
    LACUNA_CHECK(n == 3);
    LACUNA_CHECK_EQ(n, 3);
    LACUNA_CHECK_NE(n, 4);
    LACUNA_CHECK_LT(n, 4);
    LACUNA_CHECK_LE(n, 3);
    LACUNA_CHECK_GT(n, 2);
    LACUNA_CHECK_GE(n, 3);
    EXPECT_EQ(n, 3);
}

TEST(CheckDeathTest, AFailedCheckPrintsTheConditionAndBothOperandsAndAborts) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const int cells = 3;
    EXPECT_DEATH(LACUNA_CHECK_EQ(cells, 4),
                 "CHECK failed at .*check_test\\.cpp:[0-9]+: cells == 4 \\(3 vs 4\\)");
    EXPECT_DEATH(LACUNA_CHECK_LT(2.5, 1.0), "2\\.5 < 1\\.0 \\(2\\.5 vs 1\\)");
    EXPECT_DEATH(LACUNA_CHECK(cells > 5), "CHECK failed at .*: cells > 5");
}

TEST(Check, OperandsAreEvaluatedOnce) {
    int calls = 0;
    auto next = [&] { return ++calls; };
    LACUNA_CHECK_EQ(next(), 1);
    EXPECT_EQ(calls, 1);
}

TEST(Check, ADcheckIsEvaluatedOnlyWithoutNdebug) {
    int calls = 0;
    auto touch = [&] { return ++calls > 0; };
    LACUNA_DCHECK(touch());
    LACUNA_DCHECK_GE(calls, 0);
#ifdef NDEBUG
    EXPECT_EQ(calls, 0);
#else
    EXPECT_EQ(calls, 1);
    EXPECT_DEATH(LACUNA_DCHECK_EQ(calls, 7), "calls == 7 \\(1 vs 7\\)");
#endif
}

}  // namespace
}  // namespace lacuna
