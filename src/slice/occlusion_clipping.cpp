#include "slice/occlusion_clipping.h"

#include <algorithm>

namespace lacuna {

std::string to_string(OcclusionMode m) {
    switch (m) {
        case OcclusionMode::Off:
            return "off";
        case OcclusionMode::CullClip:
            return "cull+clip";
        case OcclusionMode::CullOnly:
            return "cull";
        case OcclusionMode::MapOnly:
            return "map-only";
    }
    return "?";
}

BoxClip clip_box(const OcclusionMap& map, const Vec3d& lo, const Vec3d& hi, float threshold) {
    BoxClip out{false, lo, hi};
    if (!map.valid() || !map.valid_geometry()) return out;
    const MapRect rp = map.project_box(lo, hi);
    const MapRect rv = map.visible(rp, threshold);
    if (rv.empty()) {
        out.culled = true;
        return out;
    }
    const int m = map.axis(), u = (m + 1) % 3, v = (m + 2) % 3;
    MapRect rvp = map.back_project(rv, lo[m]);
    rvp.add(map.back_project(rv, hi[m]));
    // A rounding margin (the clipped box only bounds which samples are taken; the ones it keeps
    // are computed exactly as without clipping).
    const double eps = 1e-4 * (1.0 + std::max(hi[u] - lo[u], hi[v] - lo[v]));
    out.lo[u] = std::max(lo[u], rvp.u0 - eps);
    out.hi[u] = std::min(hi[u], rvp.u1 + eps);
    out.lo[v] = std::max(lo[v], rvp.v0 - eps);
    out.hi[v] = std::min(hi[v], rvp.v1 + eps);
    if (out.lo[u] > out.hi[u] || out.lo[v] > out.hi[v]) out.culled = true;
    return out;
}

AdaptiveUpdates::AdaptiveUpdates(const AdaptiveOptions& o)
    : m_o(o), m_centre(std::max(o.initial, 0)), m_slots(size_t(2 * std::max(o.hw, 0) + 1)) {}

int AdaptiveUpdates::poll_slot() const {
    int best = 0;
    for (int s = 0; s < int(m_slots.size()); ++s) {
        const Slot& a = m_slots[size_t(s)];
        const Slot& b = m_slots[size_t(best)];
        if (!a.valid && b.valid)
            best = s;
        else if (a.valid == b.valid && a.valid && a.age > b.age)
            best = s;
    }
    return best;
}

int AdaptiveUpdates::desired() const {
    if (m_o.poll_every > 0 && m_frame % m_o.poll_every == 0)
        return std::max(0, m_centre - m_o.hw + poll_slot());
    return m_centre;
}

void AdaptiveUpdates::report(double skipped_fraction, int actual_updates) {
    const bool poll = m_o.poll_every > 0 && m_frame % m_o.poll_every == 0;
    ++m_frame;
    if (!poll) return;
    const int s = poll_slot();
    for (int i = 0; i < int(m_slots.size()); ++i) {
        Slot& slot = m_slots[size_t(i)];
        if (i == s) {
            slot = {true, 0, skipped_fraction - m_o.c * actual_updates};
        } else if (++slot.age > m_o.max_age) {
            slot.valid = false;
        }
    }
    if (!std::all_of(m_slots.begin(), m_slots.end(), [](const Slot& x) { return x.valid; })) return;
    int best = 0;
    for (int i = 1; i < int(m_slots.size()); ++i)
        if (m_slots[size_t(i)].performance > m_slots[size_t(best)].performance) best = i;
    int shift = best - m_o.hw;
    if (m_centre + shift < 0) shift = -m_centre;
    if (shift == 0) return;
    m_centre += shift;
    std::vector<Slot> moved(m_slots.size());
    for (int i = 0; i < int(m_slots.size()); ++i) {
        const int from = i + shift;
        if (from >= 0 && from < int(m_slots.size())) moved[size_t(i)] = m_slots[size_t(from)];
    }
    m_slots.swap(moved);
}

}  // namespace lacuna
