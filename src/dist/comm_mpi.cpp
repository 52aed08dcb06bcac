// dist::Comm over MPI (src/dist/comm.h): the only file that includes <mpi.h>.
// The C API only (the deprecated C++ bindings warn under -Wextra).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#include <time.h>

#include <climits>
#include <cstdlib>

#include "dist/comm.h"
#include "lacuna/error.h"

namespace lacuna::dist {

namespace {

const char* env(const char* name) {
    const char* v = std::getenv(name);
    return v && *v ? v : nullptr;
}

void finalize_at_exit() {
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
}

// Messages larger than INT_MAX bytes go in pieces (MPI counts are int).
constexpr size_t kPiece = size_t(1) << 30;

}  // namespace

bool launched() {
    return env("OMPI_COMM_WORLD_SIZE") || env("PMI_SIZE") || env("PMIX_RANK");
}

int launcher_rank() {
    for (const char* n : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const char* v = env(n)) return std::atoi(v);
    return 0;
}

Comm::Comm() {
    if (!launched()) return;  // one process; MPI untouched
    int init = 0;
    MPI_Initialized(&init);
    if (!init) {
        int provided = 0;
        // One thread at a time talks to MPI: the CLI's main thread, or the viewer's render
        // thread on rank 0 (the render's worker threads never do).
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
        std::atexit(finalize_at_exit);
    }
    int level = MPI_THREAD_SINGLE;
    MPI_Query_thread(&level);
    m_serialized = level >= MPI_THREAD_SERIALIZED;
    MPI_Comm_rank(MPI_COMM_WORLD, &m_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &m_size);
}

Comm& Comm::world() {
    static Comm c;
    return c;
}

void Comm::barrier() {
    if (m_size > 1) MPI_Barrier(MPI_COMM_WORLD);
}

void Comm::send(int to, int tag, const void* data, size_t bytes) {
    const auto* p = static_cast<const char*>(data);
    do {
        const size_t n = bytes < kPiece ? bytes : kPiece;
        MPI_Send(p, int(n), MPI_BYTE, to, tag, MPI_COMM_WORLD);
        p += n;
        bytes -= n;
    } while (bytes > 0);
}

void Comm::recv(int from, int tag, void* data, size_t bytes) {
    auto* p = static_cast<char*>(data);
    do {
        const size_t n = bytes < kPiece ? bytes : kPiece;
        MPI_Recv(p, int(n), MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        p += n;
        bytes -= n;
    } while (bytes > 0);
}

void Comm::sendrecv(int peer, int tag, const void* out, size_t out_bytes, void* in,
                    size_t in_bytes) {
    const auto* o = static_cast<const char*>(out);
    auto* i = static_cast<char*>(in);
    // Both sides walk the same number of pieces: the larger of the two sizes decides.
    do {
        const size_t no = out_bytes < kPiece ? out_bytes : kPiece;
        const size_t ni = in_bytes < kPiece ? in_bytes : kPiece;
        MPI_Sendrecv(o, int(no), MPI_BYTE, peer, tag, i, int(ni), MPI_BYTE, peer, tag,
                     MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        o += no, i += ni;
        out_bytes -= no, in_bytes -= ni;
    } while (out_bytes > 0 || in_bytes > 0);
}

void Comm::exchange(int tag, const std::vector<Transfer>& transfers) {
    std::vector<MPI_Request> req;
    req.reserve(2 * transfers.size());
    for (const Transfer& t : transfers) {
        if (t.out_bytes > size_t(INT_MAX) || t.in_bytes > size_t(INT_MAX))
            throw Error("mpi", "exchange", "expected under 2 GiB per message");
        req.emplace_back();
        MPI_Irecv(t.in, int(t.in_bytes), MPI_BYTE, t.peer, tag, MPI_COMM_WORLD, &req.back());
        req.emplace_back();
        MPI_Isend(t.out, int(t.out_bytes), MPI_BYTE, t.peer, tag, MPI_COMM_WORLD, &req.back());
    }
    MPI_Waitall(int(req.size()), req.data(), MPI_STATUSES_IGNORE);
}

std::vector<uint8_t> Comm::gather(const void* mine, size_t bytes) {
    if (bytes > size_t(INT_MAX)) throw Error("mpi", "gather", "expected under 2 GiB per rank");
    std::vector<uint8_t> all(m_rank == 0 ? bytes * size_t(m_size) : 0);
    MPI_Gather(mine, int(bytes), MPI_BYTE, all.data(), int(bytes), MPI_BYTE, 0, MPI_COMM_WORLD);
    return all;
}

void Comm::sum_to_root(std::vector<uint32_t>& v) {
    if (m_size == 1) return;
    if (v.size() > size_t(INT_MAX)) throw Error("mpi", "reduce", "expected under 2^31 counts");
    if (m_rank == 0)
        MPI_Reduce(MPI_IN_PLACE, v.data(), int(v.size()), MPI_UINT32_T, MPI_SUM, 0, MPI_COMM_WORLD);
    else
        MPI_Reduce(v.data(), nullptr, int(v.size()), MPI_UINT32_T, MPI_SUM, 0, MPI_COMM_WORLD);
}

void Comm::minmax(float& lo, float& hi) {
    if (m_size == 1) return;
    MPI_Allreduce(MPI_IN_PLACE, &lo, 1, MPI_FLOAT, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &hi, 1, MPI_FLOAT, MPI_MAX, MPI_COMM_WORLD);
}

uint64_t Comm::sum(uint64_t v) {
    if (m_size == 1) return v;
    MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return v;
}

std::vector<uint8_t> Comm::allgather(const void* mine, size_t bytes) {
    if (bytes > size_t(INT_MAX)) throw Error("mpi", "allgather", "expected under 2 GiB per rank");
    std::vector<uint8_t> all(bytes * size_t(m_size));
    MPI_Allgather(mine, int(bytes), MPI_BYTE, all.data(), int(bytes), MPI_BYTE, MPI_COMM_WORLD);
    return all;
}

// The tag of post/await, apart from every compositing round's.
constexpr int kPostTag = 0x7A11;

void Comm::post(int to, const std::vector<uint8_t>& bytes) {
    if (bytes.size() > size_t(INT_MAX)) throw Error("mpi", "post", "expected under 2 GiB");
    MPI_Send(bytes.data(), int(bytes.size()), MPI_BYTE, to, kPostTag, MPI_COMM_WORLD);
}

std::vector<uint8_t> Comm::await(int from) {
    MPI_Status st;
    for (int arrived = 0;;) {
        MPI_Iprobe(from, kPostTag, MPI_COMM_WORLD, &arrived, &st);
        if (arrived) break;
        const timespec ms{0, 1000000};
        nanosleep(&ms, nullptr);
    }
    int n = 0;
    MPI_Get_count(&st, MPI_BYTE, &n);
    std::vector<uint8_t> bytes(size_t(n < 0 ? 0 : n));
    MPI_Recv(bytes.data(), n, MPI_BYTE, from, kPostTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return bytes;
}

void Comm::abort(int code) {
    if (m_size > 1) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

}  // namespace lacuna::dist
