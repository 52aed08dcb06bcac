// The viewer under mpirun (`mpirun -np N lacuna serve VOLUME`, docs/distributed.md): rank 0 runs
// the server and renders every frame with all ranks; the other ranks follow its word here.
//
// Why a word per frame and not a collective. Every rank must call DistributedSession::render
// with the same TF and spec, in the same order, but only rank 0 knows when the page asks for a
// frame: the others wait, possibly for minutes. Waiting in a collective (MPI_Bcast) spins a core
// per rank in OpenMPI; waiting in Comm::await sleeps between probes, so an idle viewer leaves
// the machine to rank 0's server, and a frame starts within about a millisecond of the word.
//
// The word is one message to each other rank: a command byte, and for a frame the frame as a
// session document (session/session_file.h: the TF and the FrameSpec, whose round trip is
// exact), so every rank renders the frame rank 0 was asked for, bit for bit.
//
// Failures. A frame every rank refuses alike (agreed inside render()) is an Error on every rank:
// rank 0's page gets it as an error message and the followers wait for the next word. A rank's
// own failure while rendering or compositing (RankFailure) ends the job (Comm::abort), since the
// others may be waiting for its pixels.
#pragma once
#include <optional>

#include "dist/distributed_frame.h"

namespace lacuna::dist {

// Before the session: rank 0, which reads what only it needs first (the viewer's whole volume
// for its slice panes), tells the others that it started and with which TF (announce_start), or
// that it could not (announce_failure: they return from await_start with nullopt and end
// quietly, rank 0 reports its error). The followers wait for it in await_start.
void announce_start(Comm& comm, const TransferFunction& tf);
void announce_failure(Comm& comm);
std::optional<TransferFunction> await_start(Comm& comm);

// Rank 0's side. Call from one thread at a time (the server's render thread, then the main
// thread for stop()).
class RankDriver {
  public:
    explicit RankDriver(DistributedSession& session) : m_session(session) {}
    ~RankDriver() { stop(); }
    RankDriver(const RankDriver&) = delete;
    RankDriver& operator=(const RankDriver&) = delete;

    // The frame by every rank (the image on rank 0). Throws Error for a frame every rank refused.
    DistFrame frame(const TransferFunction& tf, const FrameSpec& spec);
    // DistributedSession::refine on every rank.
    void refine();
    // Releases the followers (follow_rank0 returns on each); idempotent.
    void stop();

  private:
    void tell(const std::vector<uint8_t>& word);
    DistributedSession& m_session;
    bool m_stopped = false;
};

// Ranks 1 .. N-1: renders every frame rank 0's driver asks for until it stops.
void follow_rank0(DistributedSession& session);

}  // namespace lacuna::dist
