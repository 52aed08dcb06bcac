#include "serve_mpi.h"

#include <algorithm>

namespace lacuna::cli {

FrameResult DistributedFrames::render(const TransferFunction& tf, const FrameSpec& spec) {
    check_distributable(spec);
    dist::DistFrame d = m_driver.frame(tf, spec);
    FrameResult r;
    r.image = std::move(d.image);
    r.stats.seconds = d.frame_seconds;
    r.stats.pixels = uint64_t(spec.width) * uint64_t(spec.height);
    double structure = 0;  // the slowest rank's structure work (every rank waits for it)
    for (const dist::RankReport& k : d.ranks) {
        r.stats.samples += k.samples;
        r.stats.cpu_seconds += k.cpu_seconds;
        r.stats.rays = std::max<uint64_t>(r.stats.rays, k.rays);
        structure = std::max(structure, k.build_seconds);
    }
    // The first frame builds the bricks' structures; later ones bring them to the frame's TF.
    (m_built ? r.tf_sync_seconds : r.build_seconds) = structure;
    m_built = true;
    return r;
}

}  // namespace lacuna::cli
