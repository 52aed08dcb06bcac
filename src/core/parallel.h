// The one place lacuna touches threads (STYLE.md habit 6). Algorithm files call these helpers.
#pragma once
#include <cstddef>
#include <functional>

namespace lacuna {

// Number of worker threads to use for `requested` (0 = all hardware threads).
int resolve_threads(int requested);

// Calls fn(x0, y0, x1, y1) for every tile of a width x height image, on up to `threads`
// threads. Tiles are independent, so results never depend on the thread count.
void parallel_for_tiles(int width, int height, int tile, int threads,
                        const std::function<void(int, int, int, int)>& fn);

// Calls fn(begin, end) over chunks of [0, n) on up to `threads` threads.
void parallel_for(size_t n, int threads, const std::function<void(size_t, size_t)>& fn,
                  size_t grain = 1);

// CPU time consumed so far by the calling thread, and by the whole process (all threads), in
// seconds: for "share of the work" measures that do not depend on how threads were scheduled.
double thread_cpu_seconds();
double process_cpu_seconds();

}  // namespace lacuna
