// Occlusion culling and clipping of boxes against the orthogonal opacity map (growing-boxes paper,
// Sections 4.3-4.4): the per-box test, the DeltaVoxels schedule of map updates within a frame,
// and the adaptive number of updates across frames.
#pragma once
#include <string>
#include <vector>

#include "accel/region.h"
#include "slice/occlusion_map.h"

namespace lacuna {

enum class OcclusionMode {
    Off,       // no map (the 'ESS' column)
    CullClip,  // culling and clipping ('ESS+CC')
    CullOnly,  // culling only ('ESS+C')
    MapOnly,   // every map update and box test, nothing skipped ('ESS+M': the overhead)
};
std::string to_string(OcclusionMode m);

struct OcclusionOptions {
    OcclusionMode mode = OcclusionMode::Off;
    float threshold = 0.95f;  // a cell is occluded when its minimum opacity >= threshold
    int map_size = 64;        // N of the N x N map
    int updates = 9;          // desired map updates k per frame (without an AdaptiveUpdates)
};

// Section 4.3: R_p, R_v from the hierarchical map, back-projection of R_v onto the box's front
// and back faces (planes x_m = lo_m and hi_m), union -> R_vp. Index-space boxes.
struct BoxClip {
    bool culled = false;
    Vec3d lo{}, hi{};  // the clipped box (= the input when nothing is clipped)
};
BoxClip clip_box(const OcclusionMap& map, const Vec3d& lo, const Vec3d& hi, float threshold);

// Section 4.4: a window of 2*hw+1 slots centred at k holds the performance p = v - c*k' of
// k-hw .. k+hw updates (v: share of non-empty voxels culled or clipped, k': actual updates). Every
// n-th frame polls the slot not measured for the longest; every other slot ages by one and
// becomes invalid past max_age. When all slots are valid the best one becomes the new centre and
// the window shifts with it (slots that fall off are dropped, new ones are invalid).
struct AdaptiveOptions {
    int initial = 9;  // k
    int hw = 3;
    int poll_every = 10;  // n
    double c = 0.02;
    int max_age = 14;  // polls
};

class AdaptiveUpdates {
  public:
    explicit AdaptiveUpdates(const AdaptiveOptions& o = {});
    // Desired number of updates for the next frame.
    int desired() const;
    // Reports the frame just rendered with desired() updates.
    void report(double skipped_fraction, int actual_updates);
    int centre() const { return m_centre; }
    int frame() const { return m_frame; }

  private:
    struct Slot {
        bool valid = false;
        int age = 0;
        double performance = 0;
    };
    int poll_slot() const;
    AdaptiveOptions m_o;
    int m_centre;
    int m_frame = 0;
    std::vector<Slot> m_slots;
};

}  // namespace lacuna
