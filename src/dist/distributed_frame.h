// One frame rendered by every rank of a job (docs/distributed.md): the front ends' entry.
//
// Every rank calls render_distributed with the same FrameSpec and TF (the CLI's flags, parsed the
// same way on every rank). Each rank
//   1. loads its brick (brick_io.h) of the decomposition (decomposition.h), computed the same way
//      on every rank from the whole grid (and, for Balance::Visible, the TF). By offset with
//      Balance::Visible, a rank first reads its slab (its brick of the voxel-balanced tree),
//      counts the visible cells of the slab, and the ranks build the visible tree from the sums
//      of their counts (decompose_visible_slabs); then it reads its brick of that tree (the slab
//      kept when they are the same box);
//   2. runs an ordinary Session over the brick (Session::set_brick): the structure of the frame is
//      built over the brick, and the ray marcher takes only the brick's owned samples of the whole
//      grid's lattice (render/ownership.h), without early ray termination;
//   3. composites its partial float image with the others' (composite.h); rank 0 ends with the
//      frame, the background composited and rounded by the single-process pixel rule.
// So the frame equals the single-process frame rendered with early termination off (--ert 1), up
// to the float association of compositing (within 1/255 per channel; tests/dist/).
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "dist/brick_io.h"
#include "dist/comm.h"
#include "dist/composite.h"
#include "dist/decomposition.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::dist {

struct DistOptions {
    Balance balance = Balance::Voxels;
    Composite composite = Composite::Direct;
    int radix = 4;  // radix-k's k
};

// One rank's account of the frame (plain data: gathered on rank 0 as bytes).
struct RankReport {
    int32_t rank = 0;
    int32_t pad = 0;
    double load_seconds = 0;       // read the file and cut the brick out
    double build_seconds = 0;      // the brick's structure (and its per-TF refinement)
    double render_seconds = 0;     // the rank's owned samples
    double composite_seconds = 0;  // this rank's part of compositing (after every render)
    double cpu_seconds = 0;        // CPU time of the render (all its threads)
    uint64_t samples = 0, rays = 0;
    uint64_t voxels = 0;       // voxels of the brick (ghost layer included)
    uint64_t voxels_read = 0;  // voxels read from the file (the brick's (and with --balance
                               // visible the slab's), or the whole file's)
    uint64_t visible_cells =
        0;  // cells of the brick's box the TF can make visible (0: not counted)
    uint64_t bytes_sent = 0;
    uint64_t peak_rss_kib =
        0;  // the rank's peak resident memory at the frame's end  // compositing
};

struct DistFrame {
    Image image;  // rank 0 only
    // Per pixel, the samples of every rank summed (rank 0, when the spec's count_samples): the
    // single-process counts of --accel none exactly (every lattice sample once).
    std::vector<uint32_t> sample_counts;
    std::vector<RankReport> ranks;  // rank 0 only, in rank order
    Decomposition decomposition;
    uint64_t whole_voxels = 0;
    double frame_seconds = 0;  // rank 0: from the render's start to the composited image
};

// The whole volume once per rank, through the front end's reader.
using VolumeLoader = std::function<Volume()>;

// Where the ranks' voxels come from (brick_io.h).
struct VolumeSource {
    VolumeLoader load_whole;              // any file: read whole by every rank, the brick cut out
    std::optional<io::BrickFile> file;    // set: bricks read by offset (src/io/brick_read.h)
    MemoryBudget budget;                  // what a rank may read by offset (--max-memory)
    std::optional<ValueRange> vis_range;  // the front end's visualization range (--range), if any
};

// Worker threads of a rank: `requested`, or for 0 the cores this process may run on (its CPU
// affinity, which mpirun sets when it binds ranks to cores).
int rank_threads(int requested);

// A failure of one rank after every rank has loaded its brick and built its structure (then the
// others may be waiting for its messages): the front end ends the job (Comm::abort). Failures
// before that (a missing file, a bad frame) are every rank's alike and thrown as they are, on
// every rank.
struct RankFailure : Error {
    using Error::Error;
};

// A job's bricks kept across frames (the viewer under mpirun, src/dist/rank_loop.h): step 1
// once, when constructed; steps 2 and 3 per frame. Every rank constructs it with the same
// arguments and then calls render() and refine() with the same TF and spec in the same order.
// With Balance::Visible the bricks are balanced on the constructor's TF and kept for every
// later TF: a frame of another TF is as exact, only less balanced.
class DistributedSession {
  public:
    // `threads` as rank_threads() resolves it. Failures are agreed as in render_distributed.
    DistributedSession(Comm& comm, const VolumeSource& source, const TransferFunction& tf,
                       const DistOptions& options, int threads);
    ~DistributedSession();
    DistributedSession(const DistributedSession&) = delete;
    DistributedSession& operator=(const DistributedSession&) = delete;

    // Steps 2 and 3 for one frame (spec's early termination ignored: see the top). With `refine`
    // the structure's per-TF refinement (Session::refine) is computed before the frame (one
    // frame of the CLI; the viewer refines between frames). A failure every rank learns before
    // rendering (a spec the session refuses) is thrown as lacuna::Error on every rank and leaves
    // the session usable; a rank's own failure while rendering or compositing is a RankFailure.
    DistFrame render(const TransferFunction& tf, const FrameSpec& spec, bool refine = false);
    // Session::refine on every rank's brick.
    void refine();

    Comm& comm() const { return m_comm; }
    const Decomposition& decomposition() const { return m_decomposition; }
    int threads() const { return m_threads; }

  private:
    Comm& m_comm;
    DistOptions m_options;
    int m_threads;
    Decomposition m_decomposition;
    BrickOwnership m_own;
    Box3f m_whole_bounds;
    uint64_t m_whole_voxels = 0;
    RankReport m_loaded;                 // load_seconds, voxels, voxels_read
    std::unique_ptr<Session> m_session;  // over the brick
};

// One frame: a DistributedSession for it, refined, rendered. `threads` as rank_threads().
DistFrame render_distributed(Comm& comm, const VolumeSource& source, const TransferFunction& tf,
                             const FrameSpec& spec, const DistOptions& options, int threads);

}  // namespace lacuna::dist
