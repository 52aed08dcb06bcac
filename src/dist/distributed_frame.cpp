#include "dist/distributed_frame.h"

#include <malloc.h>
#include <sched.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>

#include "core/parallel.h"
#include "dist/brick_io.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"
#include "lacuna/session.h"
#include "render/pixel_driver.h"

namespace lacuna::dist {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

// Whether any rank failed, learnt by every rank before any waits in the frame's collectives: a
// failure becomes an exception on every rank (a failed rank's own; on the others the first
// failed rank's message), so every rank leaves the frame and the CLI prints one line (rank 0's).
static void agree(Comm& comm, const std::exception_ptr& failed, const std::string& what) {
    struct Word {
        int32_t failed;
        char what[508];
    };
    Word mine{};
    mine.failed = failed ? 1 : 0;
    std::snprintf(mine.what, sizeof mine.what, "%s", what.c_str());
    const std::vector<uint8_t> all = comm.allgather(&mine, sizeof mine);
    if (failed) std::rethrow_exception(failed);
    for (int r = 0; r < comm.size(); ++r) {
        Word w;
        std::memcpy(&w, all.data() + size_t(r) * sizeof w, sizeof w);
        w.what[sizeof w.what - 1] = 0;
        if (w.failed) throw Error("rank " + std::to_string(r) + ": " + w.what);
    }
}

int rank_threads(int requested) {
    if (requested > 0) return requested;
    // mpirun binds each rank to its share of the cores (unless oversubscribed): all of them
    // would be more threads than this rank may run (TBB warns and caps them).
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
    return resolve_threads(0);
}

DistributedSession::DistributedSession(Comm& comm, const VolumeSource& source,
                                       const TransferFunction& tf, const DistOptions& options,
                                       int threads)
    : m_comm(comm), m_options(options), m_threads(rank_threads(threads)) {
    // Freed buffers stay in the heap: every frame allocates and frees image-sized buffers (the
    // partials, compositing's pieces and strips), and on a VM each first touch of a page the
    // kernel hands out again costs tens of microseconds (docs/distributed.md, "Compositing cost
    // model"), which would swamp a warm frame's compositing. Process-wide, as `lacuna bench mpi
    // --worker` does; only distributed front ends construct this.
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    threads = m_threads;
    DistFrame out;  // its decomposition and whole_voxels, kept as the members below
    RankReport& me = m_loaded;
    me.rank = comm.rank();
    // 1. The whole grid, its decomposition, this rank's brick.
    auto t0 = Clock::now();
    Box3f whole_bounds;
    Volume brick;
    ValueRange vis{};
    std::optional<SlabCounts> counts;
    BrickOwnership own;
    const bool by_offset = source.file.has_value();
    const bool visible = options.balance == Balance::Visible;
    float lo = 0, hi = 0;
    std::exception_ptr failed;
    std::string what;
    try {
        if (by_offset) {
            // By offset: the header alone gives the grid; each rank reads its brick (for a
            // visible balance first its slab of the voxel-balanced tree), then all agree on the
            // whole volume's range from their voxels' (which cover every voxel).
            const Volume& header = source.file->header;
            whole_bounds = world_bounds(header);
            out.whole_voxels = header.voxel_count();
            out.decomposition = decompose_voxels(header.dims(), comm.size());
            own = ownership(out.decomposition, comm.rank());
            brick = io::read_brick(*source.file, own.offset,
                                   brick_voxels(out.decomposition, comm.rank()), source.budget);
            me.voxels_read = brick.voxel_count();
            finite_minmax(brick, lo, hi);
        } else {
            const Volume whole = source.load_whole();
            whole_bounds = world_bounds(whole);
            out.whole_voxels = whole.voxel_count();
            me.voxels_read = whole.voxel_count();
            out.decomposition = visible
                                    ? decompose_visible(whole, discretise(tf, whole.vis_range()),
                                                        comm.size(), threads)
                                    : decompose_voxels(whole.dims(), comm.size());
            own = ownership(out.decomposition, comm.rank());
            brick = crop_brick(whole, own.offset, brick_voxels(out.decomposition, comm.rank()));
        }
    } catch (const std::exception& e) {
        failed = std::current_exception();
        what = e.what();
    }
    agree(comm, failed, what);
    if (by_offset) {
        // What read_volume does with the whole volume (brick_io.h): the range, NaN as its
        // smallest value, the visualization range; for a visible balance, the visible cells of
        // this rank's slab (the brick just read), the tree of them and this rank's brick of it.
        comm.minmax(lo, hi);
        const std::string& path = source.file->path;
        auto finish = [&](Volume& v) {  // read_volume's last steps, with the whole volume's values
            replace_nan(v, lo);
            v.compute_range(path);
            v.set_vis_range(vis);
        };
        try {
            if (!(lo <= hi))
                throw Error(path, "voxel values",
                            "expected at least one voxel that is not NaN, got NaN only");
            vis = source.vis_range ? *source.vis_range : default_vis_range(lo, hi);
            finish(brick);
            if (visible)
                counts.emplace(brick, own.offset, out.decomposition.bricks[size_t(comm.rank())],
                               discretise(tf, vis), threads);
        } catch (const std::exception& e) {
            failed = std::current_exception();
            what = e.what();
        }
        agree(comm, failed, what);
        if (visible) {
            // The tree of the visible cells from every slab's counts; this rank's brick of it
            // (the slab itself when the box is the same).
            const CellBox slab = out.decomposition.bricks[size_t(comm.rank())];
            out.decomposition =
                decompose_visible_slabs(source.file->header.dims(), *counts, comm.size(),
                                        [&](uint64_t v) { return comm.sum(v); });
            counts.reset();
            own = ownership(out.decomposition, comm.rank());
            const CellBox& c = out.decomposition.bricks[size_t(comm.rank())];
            try {
                if (!std::equal(c.lo, c.lo + 3, slab.lo) || !std::equal(c.hi, c.hi + 3, slab.hi)) {
                    brick = Volume();  // the slab's voxels go before the brick's come
                    brick =
                        io::read_brick(*source.file, own.offset,
                                       brick_voxels(out.decomposition, comm.rank()), source.budget);
                    me.voxels_read += brick.voxel_count();
                    finish(brick);
                }
            } catch (const std::exception& e) {
                failed = std::current_exception();
                what = e.what();
            }
            agree(comm, failed, what);
        }
    }
    me.load_seconds = seconds_since(t0);
    me.voxels = brick.voxel_count();
    m_decomposition = std::move(out.decomposition);
    m_whole_voxels = out.whole_voxels;
    m_own = own;
    m_whole_bounds = whole_bounds;
    // 2 (once). The brick's session; its structures are built by the first frame.
    try {
        m_session = std::make_unique<Session>(std::move(brick), threads);
        m_session->set_brick(own, whole_bounds);
    } catch (const std::exception& e) {
        failed = std::current_exception();
        what = e.what();
    }
    agree(comm, failed, what);
}

DistributedSession::~DistributedSession() = default;

void DistributedSession::refine() {
    std::exception_ptr failed;
    std::string what;
    try {
        m_session->refine();
    } catch (const std::exception& e) {
        failed = std::current_exception();
        what = e.what();
    }
    agree(m_comm, failed, what);
}

DistFrame DistributedSession::render(const TransferFunction& tf, const FrameSpec& spec,
                                     bool refine) {
    Comm& comm = m_comm;
    Session* session = m_session.get();
    DistFrame out;
    out.decomposition = m_decomposition;
    out.whole_voxels = m_whole_voxels;
    RankReport me = m_loaded;
    FrameSpec f = spec;
    f.keep_float = true;
    f.sampling.early_termination.reset();  // a rank cannot see the opacity in front of its brick
    std::exception_ptr failed;
    std::string what;
    // 2. The brick's structure for this frame's TF.
    const auto t0 = Clock::now();
    try {
        session->set_transfer_function(tf);
        session->prepare(f);
        if (refine) session->refine();
    } catch (const std::exception& e) {
        failed = std::current_exception();
        what = e.what();
    }
    agree(comm, failed, what);
    me.build_seconds = seconds_since(t0);
    // 3. Render and composite. A failure now is this rank's alone while the others may wait
    // for its messages: it leaves as a RankFailure, which ends the job.
    try {
        comm.barrier();  // the frame's time starts when every rank is ready
        const auto frame0 = Clock::now();
        FrameResult r = session->render(f);
        me.render_seconds = r.stats.seconds;
        me.cpu_seconds = r.stats.cpu_seconds;
        me.samples = r.stats.samples;
        me.rays = r.stats.rays;
        // Compositing starts when every rank has rendered, so its time is its own (not the wait
        // for the slowest render, which the frame's time holds).
        comm.barrier();
        // 3. Compositing in the kd-tree's order for this view (eye and ray direction in whole index
        // space: the volume frame over the spacing).
        const Camera cam = to_volume_frame(volume_frame(session->volume()), session->camera(f));
        const Vec3d sp = session->volume().spacing;
        const Vec3f inv{float(1.0 / sp.x), float(1.0 / sp.y), float(1.0 / sp.z)};
        const Vec3f eye = cam.eye() * inv, dir = cam.forward() * inv;
        const bool ortho = cam.projection() == Projection::Orthographic;
        Partial mine{f.width, f.height, std::move(r.rgba_float)};
        CompositeStats cs;
        Partial done;
        switch (m_options.composite) {
            case Composite::Direct:
                done = composite_direct(comm, mine,
                                        visibility_order(out.decomposition, eye, dir, ortho), cs);
                break;
            case Composite::BinarySwap:
                done = composite_binary_swap(comm, std::move(mine), out.decomposition, eye, dir,
                                             ortho, cs);
                break;
            case Composite::RadixK:
                done = composite_radix_k(comm, std::move(mine), out.decomposition, eye, dir, ortho,
                                         m_options.radix, cs);
                break;
        }
        if (f.count_samples) {
            comm.sum_to_root(r.sample_counts);
            if (comm.rank() == 0) out.sample_counts = std::move(r.sample_counts);
        }
        me.composite_seconds = cs.seconds;
        me.bytes_sent = cs.bytes_sent;
        if (comm.rank() == 0) {
            // The single-process pixel rule (pixel_driver.h): background behind, clamp, round.
            out.image = Image(f.width, f.height);
            for (int y = 0; y < f.height; ++y)
                for (int x = 0; x < f.width; ++x) {
                    const float* c = done.at(x, y);
                    const uint32_t w =
                        pixel_word(f.background, kernel::Accum{c[0], c[1], c[2], c[3]});
                    std::memcpy(out.image.pixel(x, y), &w, 4);
                }
            out.frame_seconds = seconds_since(frame0);
        }
        // 4. Every rank's report on rank 0.
        rusage ru{};
        if (getrusage(RUSAGE_SELF, &ru) == 0) me.peak_rss_kib = uint64_t(ru.ru_maxrss);
        const std::vector<uint8_t> all = comm.gather(&me, sizeof me);
        if (comm.rank() == 0) {
            out.ranks.resize(size_t(comm.size()));
            std::memcpy(out.ranks.data(), all.data(), all.size());
        }
    } catch (const std::exception& e) {
        if (comm.size() == 1) throw;
        throw RankFailure("rank " + std::to_string(comm.rank()) + ": " + e.what());
    }
    return out;
}

DistFrame render_distributed(Comm& comm, const VolumeSource& source, const TransferFunction& tf,
                             const FrameSpec& spec, const DistOptions& options, int threads) {
    DistributedSession session(comm, source, tf, options, threads);
    return session.render(tf, spec, /*refine=*/true);
}

}  // namespace lacuna::dist
