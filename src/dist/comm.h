// The one place distributed rendering talks to MPI (STYLE.md habit 6: like threading and SIMD,
// message passing lives in one file). Built over MPI (comm_mpi.cpp) when CMake finds it, else
// over a one-process stand-in (comm_single.cpp) with the same interface, so everything above it
// (decomposition, compositing, the distributed frame) compiles and is tested without MPI.
//
// MPI is initialised lazily, and only when the process was started by a launcher (mpirun sets
// OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK): a plain `lacuna render` never touches MPI, and
// its behaviour is unchanged. Finalised at exit. Any one thread at a time may call a Comm
// (MPI_THREAD_SERIALIZED, when the library provides it); the render's worker threads never do.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lacuna::dist {

// True when this process was started by an MPI launcher and lacuna was built with MPI.
bool launched();
// The launcher's rank of this process from its environment, without initialising MPI (0 when
// not launched): the CLI prints errors on rank 0 only.
int launcher_rank();

// COMM_WORLD (initialising MPI on first use when launched; one process of rank 0 otherwise).
class Comm {
  public:
    static Comm& world();
    int rank() const { return m_rank; }
    int size() const { return m_size; }

    void barrier();
    // Raw bytes, blocking. Tags keep the compositing rounds apart.
    void send(int to, int tag, const void* data, size_t bytes);
    void recv(int from, int tag, void* data, size_t bytes);
    // Exchanges with `peer` at once (no deadlock whichever side is first).
    void sendrecv(int peer, int tag, const void* out, size_t out_bytes, void* in, size_t in_bytes);
    // Exchanges with several peers at once: transfer i sends `out` to `peer` and receives `in`
    // (its size known) from it. Every transfer is posted before any is waited for, so no order
    // of the peers can deadlock and no pair waits for another pair's turn (radix-k's rounds).
    struct Transfer {
        int peer;
        const void* out;
        size_t out_bytes;
        void* in;
        size_t in_bytes;
    };
    void exchange(int tag, const std::vector<Transfer>& transfers);
    // Every rank's `mine` (the same size everywhere) on rank 0, in rank order.
    std::vector<uint8_t> gather(const void* mine, size_t bytes);
    // The element-wise sum of every rank's `v` (the same length everywhere) into rank 0's `v`
    // (the other ranks' are left as they were).
    void sum_to_root(std::vector<uint32_t>& v);
    // The smallest `lo` and the largest `hi` over every rank, on every rank.
    void minmax(float& lo, float& hi);
    // The sum of every rank's `v`, on every rank.
    uint64_t sum(uint64_t v);
    // Every rank's `mine` on every rank, in rank order.
    std::vector<uint8_t> allgather(const void* mine, size_t bytes);
    // A message of any length to `to` alone, and its receipt on `from`'s side (the viewer's
    // commands, rank_loop.h). await() waits by probing with a sleep of about a millisecond
    // between probes instead of spinning, so a rank that waits for the next frame leaves its
    // core to the others (an idle viewer's ranks cost nothing).
    void post(int to, const std::vector<uint8_t>& bytes);
    std::vector<uint8_t> await(int from);
    // Whether any thread may talk to MPI, one at a time (MPI_THREAD_SERIALIZED): the viewer's
    // rank 0 renders on its render thread. Always true for one process.
    bool serialized_threads() const { return m_serialized; }
    // Ends every rank of the job with this exit code (after a rank's error: the others may be
    // waiting in a collective).
    [[noreturn]] void abort(int code);

  private:
    Comm();
    int m_rank = 0, m_size = 1;
    bool m_serialized = true;
};

}  // namespace lacuna::dist
