// The object-order renderer of the growing-boxes paper: view-aligned slicing planes through a
// list of boxes in visibility order, front to back, each box's slicing polygons computed
// incrementally (slice/polygon.h) and rasterised into an RGBA float framebuffer, with optional
// occlusion culling and clipping (slice/occlusion_clipping.h). docs/slicer.md.
//
// Sample lattice (what makes every box source give the bytes of the one-box 'Basic' render):
//   plane k        world points X with dot(X - eye, forward) = z_k = (k + 0.5) * dt, k >= 0,
//                  dt = step * min(spacing): anchored at the eye, independent of any box
//   sample (p, k)  the point of pixel p's ray (Camera::generate) on plane k:
//                  t = (z_k - a_p) * c_p, a_p = dot(origin_p - eye, forward),
//                  c_p = 1 / dot(dir_p, forward); P = o_p + t * d_p in index space
//   ownership      box [lo, hi] owns P when lo <= P < hi on every axis (P <= hi where hi is the
//                  volume's last voxel): every point of the volume has exactly one owner in a
//                  partition, and the trilinear cell of an owned P lies in the box
// A polygon only says which pixels to try; the ownership test decides, so a sample is taken once,
// from whichever box owns it, with the same arithmetic. Boxes come in visibility order, so each
// pixel composites its samples in increasing k, as Basic does. Boxes a source leaves out hold only
// cells whose TF opacity is exactly 0 (compositing their samples is the identity).
//
// Threads: the framebuffer is cut into tiles; a tile composites every box of a batch in order.
// Occlusion batches (boxes between two map updates) are rendered one after the other, so the
// bytes never depend on the thread count.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "lacuna/camera.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"
#include "slice/box_source.h"
#include "slice/occlusion_clipping.h"

namespace lacuna {

struct SliceOptions {
    float step = 0.5f;                // plane distance in units of the smallest voxel spacing
    float ert = kNoEarlyTermination;  // per-pixel early termination opacity (>= 1: off, as on the
                                      // paper's GPU)
    int threads = 0;                  // 0 = all hardware threads
    Vec3f background{0, 0, 0};
    bool keep_float = false;  // fill SliceResult::rgba_float
    bool nearest = false;     // nearest-voxel samples (lacuna/accel.h, Interpolation::Nearest)
    int tile = 32;            // framebuffer tile edge in pixels
    OcclusionOptions occlusion;
};

struct SliceStats {
    double seconds = 0;            // whole frame
    double setup_seconds = 0;      // slicing polygons (incremental intersection + projection)
    double cpu_seconds = 0;        // process CPU time of the frame (all threads)
    double setup_cpu_seconds = 0;  // CPU time of the slicing polygons (all threads)
    double occlusion_seconds = 0;  // map updates, culling and clipping
    uint64_t samples = 0;          // composited samples
    uint64_t polygons = 0;         // non-empty slicing polygons
    uint64_t boxes = 0, boxes_culled = 0, boxes_clipped = 0;
    double voxels = 0;  // cells in the source's boxes (the non-empty voxels)
    double voxels_culled = 0, voxels_clipped = 0;
    int desired_updates = 0, map_updates = 0;
    double setup_fraction() const { return seconds > 0 ? setup_seconds / seconds : 0; }
    // Share of the frame's CPU time: what the polygons cost, whatever the thread scheduling.
    double setup_cpu_fraction() const {
        return cpu_seconds > 0 ? std::min(1.0, setup_cpu_seconds / cpu_seconds) : 0;
    }
    double culled_fraction() const { return voxels > 0 ? voxels_culled / voxels : 0; }
    double clipped_fraction() const { return voxels > 0 ? voxels_clipped / voxels : 0; }
    double skipped_fraction() const { return culled_fraction() + clipped_fraction(); }
};
std::string to_string(const SliceStats& s);

struct SliceResult {
    Image image;
    std::vector<float> rgba_float;  // premultiplied RGBA before background and rounding
    SliceStats stats;
};

class SliceRenderer {
  public:
    explicit SliceRenderer(const Volume& volume);  // the volume must outlive the renderer
    void set_transfer_function(const TransferLut& lut);
    // The boxes to render (nullptr: the whole volume, 'Basic'). Must outlive the renders and
    // already have the current TF.
    void set_box_source(const BoxSource* source) { m_source = source; }
    // `adaptive` (may be null): the number of map updates per frame is taken from it and the
    // frame reported back (Section 4.4); otherwise options.occlusion.updates.
    SliceResult render(const Camera& camera, const SliceOptions& options,
                       AdaptiveUpdates* adaptive = nullptr) const;
    Box3f bounds() const;

  private:
    const Volume& m_volume;
    TransferLut m_lut;
    const BoxSource* m_source = nullptr;
};

}  // namespace lacuna
