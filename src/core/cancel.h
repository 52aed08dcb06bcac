// Cancelling a frame in progress (the viewer: a newer request of the same tab, or the tab's
// closing, cancels the render on the render thread; docs/viewer.md, "Render budget").
//
// A CancelScope makes `flag` the calling thread's cancellation flag while it lives.
// parallel_for_tiles (core/parallel.h) called on that thread reads the flag before every tile:
// once it is set no further tile starts, and the call throws Cancelled after the tiles already
// running have ended (their pixels are then incomplete: a cancelled frame is thrown away).
// Without a scope nothing changes (the CLI, the benchmarks, the tests of the renderers). The
// flag is only read here; whoever cancels sets it, from any thread. Structure builds
// (parallel_for) are not cancelled.
#pragma once
#include <atomic>
#include <exception>

namespace lacuna {

struct Cancelled : std::exception {
    const char* what() const noexcept override { return "cancelled"; }
};

class CancelScope {
  public:
    explicit CancelScope(const std::atomic<bool>& flag);
    ~CancelScope();  // the enclosing scope's flag (or none) again
    CancelScope(const CancelScope&) = delete;
    CancelScope& operator=(const CancelScope&) = delete;

  private:
    const std::atomic<bool>* m_previous;
};

// The calling thread's flag, nullptr outside every scope.
const std::atomic<bool>* current_cancel_flag();

}  // namespace lacuna
