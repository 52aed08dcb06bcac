// core/cancel.h: a CancelScope's flag stops parallel_for_tiles between tiles (the viewer's
// frame cancellation); without a scope, or with the flag clear, every tile runs.
#include "core/cancel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "core/parallel.h"

namespace {

using namespace lacuna;

TEST(Cancel, AFlagSetDuringATileStopsTheTilesAfterIt) {
    // One thread: the tiles run one after the other, so exactly the first three ran.
    std::atomic<bool> flag{false};
    std::atomic<int> calls{0};
    const CancelScope scope(flag);
    EXPECT_THROW(parallel_for_tiles(64, 64, 8, 1,
                                    [&](int, int, int, int) {
                                        if (++calls == 3) flag = true;
                                    }),
                 Cancelled);
    EXPECT_EQ(calls, 3);
    // Two threads: a tile may begin after the flag was set only if the other thread had
    // checked it just before, so at most one such tile. (Tiles after the third wait for the
    // flag, so the other thread cannot finish the image before the third tile sets it.)
    flag = false;
    calls = 0;
    std::atomic<int> late{0};
    EXPECT_THROW(parallel_for_tiles(64, 64, 8, 2,
                                    [&](int, int, int, int) {
                                        if (flag) ++late;
                                        const int n = ++calls;
                                        if (n == 3) flag = true;
                                        while (n > 3 && !flag) std::this_thread::yield();
                                    }),
                 Cancelled);
    EXPECT_LE(late, 1);
    EXPECT_LE(calls, 4);
}

TEST(Cancel, ASetFlagStartsNoTile) {
    std::atomic<bool> flag{true};
    int calls = 0;
    const CancelScope scope(flag);
    EXPECT_THROW(parallel_for_tiles(64, 64, 8, 2, [&](int, int, int, int) { ++calls; }), Cancelled);
    EXPECT_EQ(calls, 0);
}

TEST(Cancel, WithoutAScopeOrAFlagEveryTileRunsAndScopesNest) {
    std::atomic<int> calls{0};
    const auto count = [&](int, int, int, int) { ++calls; };
    EXPECT_EQ(current_cancel_flag(), nullptr);
    parallel_for_tiles(70, 50, 8, 2, count);  // 9 x 7 tiles
    EXPECT_EQ(calls, 63);
    std::atomic<bool> outer{false}, inner{true};
    {
        const CancelScope a(outer);
        EXPECT_EQ(current_cancel_flag(), &outer);
        {
            const CancelScope b(inner);
            EXPECT_EQ(current_cancel_flag(), &inner);
            EXPECT_THROW(parallel_for_tiles(70, 50, 8, 2, count), Cancelled);
        }
        EXPECT_EQ(current_cancel_flag(), &outer);
        parallel_for_tiles(70, 50, 8, 2, count);  // the outer flag is clear: all of them
        EXPECT_EQ(calls, 126);
    }
    EXPECT_EQ(current_cancel_flag(), nullptr);
    // The flag belongs to the thread that opened the scope, not to the process.
    std::atomic<bool> set{true};
    const CancelScope c(set);
    std::thread other([&] {
        EXPECT_EQ(current_cancel_flag(), nullptr);
        parallel_for_tiles(70, 50, 8, 1, count);
    });
    other.join();
    EXPECT_EQ(calls, 189);
}

}  // namespace
