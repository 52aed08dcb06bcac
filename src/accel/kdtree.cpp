#include "accel/kdtree.h"

#include <chrono>

#include "accel/cell_ranges.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {
int* grid_cells(const Volume& v, int c[3]) {
    cell_counts(v, c);
    return c;
}
}  // namespace

KdTree::KdTree(const Volume& v, const AccelOptions& o)
    : Accel(AccelKind::KdTree), m_volume(v), m_settings(kd_settings(o)) {
    if (o.kd_threshold)
        throw FrameError("structure.threshold",
                         "a value threshold is for `lacuna partition` only; rendering with the "
                         "kd-tree classifies cells by the transfer function");
    // Nothing is TF-independent; until the first TF every cell may be visible.
    int c[3];
    m_part = KdPartition(grid_cells(v, c));
    m_stats.nodes = m_part.nodes().size();
    m_stats.bytes = m_part.bytes();
}

void KdTree::set_transfer_function(const TransferLut& lut) {
    const auto t0 = std::chrono::steady_clock::now();
    m_part.build_from_tf(m_volume, lut, m_settings);
    m_stats.tf_update_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_stats.build_seconds = m_stats.tf_update_seconds;
    m_stats.nodes = m_part.nodes().size();
    m_stats.bytes = m_part.bytes();
}

}  // namespace lacuna
