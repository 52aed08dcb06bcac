#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <ctime>
#include <thread>

#include "core/cancel.h"

namespace lacuna {

int resolve_threads(int requested) {
    int hw = int(std::thread::hardware_concurrency());
    if (hw <= 0) hw = 1;
    return requested > 0 ? requested : hw;
}

namespace {
thread_local const std::atomic<bool>* t_cancel = nullptr;  // core/cancel.h
}  // namespace

CancelScope::CancelScope(const std::atomic<bool>& flag) : m_previous(t_cancel) {
    t_cancel = &flag;
}
CancelScope::~CancelScope() {
    t_cancel = m_previous;
}
const std::atomic<bool>* current_cancel_flag() {
    return t_cancel;
}

void parallel_for_tiles(int width, int height, int tile, int threads,
                        const std::function<void(int, int, int, int)>& fn) {
    const int tx = (width + tile - 1) / tile, ty = (height + tile - 1) / tile;
    // The caller's cancellation flag (read here: the tiles run on TBB's threads), checked
    // before every tile.
    const std::atomic<bool>* cancel = t_cancel;
    std::atomic<bool> stopped{false};
    tbb::task_arena arena(resolve_threads(threads));
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, tx * ty, 1),
            [&](const tbb::blocked_range<int>& r) {
                for (int t = r.begin(); t != r.end(); ++t) {
                    if (cancel && cancel->load(std::memory_order_relaxed)) {
                        stopped.store(true, std::memory_order_relaxed);
                        return;
                    }
                    int x0 = (t % tx) * tile, y0 = (t / tx) * tile;
                    fn(x0, y0, std::min(x0 + tile, width), std::min(y0 + tile, height));
                }
            },
            tbb::simple_partitioner());
    });
    if (stopped.load()) throw Cancelled();
}

void parallel_for(size_t n, int threads, const std::function<void(size_t, size_t)>& fn,
                  size_t grain) {
    tbb::task_arena arena(resolve_threads(threads));
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain),
                          [&](const tbb::blocked_range<size_t>& r) { fn(r.begin(), r.end()); });
    });
}

double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace lacuna
