// The viewer's renderer: owns the volume, the skipping structures (built lazily, the first time
// a frame asks for one) and the ray marcher, and turns a ViewRequest into an image with the
// numbers the page's overlay shows. Not thread-safe: the server calls it from one render thread.
//
// For the same settings a frame is the image `lacuna render` writes (tested): the camera is
// Camera::orbit with the request's azimuth, elevation and zoom (fov 30, perspective), ert 0.99 or
// off, black background.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/segments.h"
#include "lacuna/volume.h"
#include "serve/protocol.h"
#include "slice/box_source.h"
#include "slice/slice_renderer.h"

namespace lacuna::serve {

struct Frame {
    Image image;
    RenderStats stats;
    uint64_t lattice_samples = 0;        // samples the reference (no skipping, no ERT) would take
    double skipped = 0;                  // 1 - samples / lattice_samples
    bool tf_changed = false;             // this frame applied a TF different from the previous one
    double tf_update_seconds = 0;        // LUT + marcher + structure update, when tf_changed
    double accel_build_seconds = 0;      // when this frame built its structure for the first time
    double accel_tf_update_seconds = 0;  // the structure's last TF update (AccelStats)
};

class FrameRenderer {
  public:
    // threads: render and build threads (0 = all). The renderer keeps the volume.
    FrameRenderer(Volume volume, const AccelOptions& accel_options = {}, int threads = 0);
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    const Volume& volume() const { return *m_volume; }
    // A label volume (same dims) for the page's segments toggle (docs/segments.md). Throws
    // lacuna::Error if it cannot be a label map of this volume.
    void set_labels(Volume labels);
    int label_count() const { return m_labels ? m_label_table.size() : 0; }
    // Voxel counts in kHistogramBins equal bins over the visualization range.
    static constexpr int kHistogramBins = 256;
    const std::vector<uint64_t>& histogram() const { return m_histogram; }

    // Renders `req` at width x height (the server passes a reduced size for previews).
    Frame render(const ViewRequest& req, int width, int height);
    // Computes the built structures' finer per-TF level (Accel::refine) for the current TF:
    // the server calls it when the render thread is idle, after a frame went out, so a TF edit
    // never waits for it and the frames after it use it.
    void refine();

    // The camera a request describes, for an image of width x height.
    Camera camera(const ViewCamera& c, int width, int height) const;
    // The marcher's options for a request (what `lacuna render --step S --ert 0.99|1` uses).
    RenderOptions render_options(const ViewRequest& req) const;

  private:
    Accel& accel(AccelKind k, double& build_seconds);

    std::unique_ptr<Volume> m_volume;  // stable address: marcher and structures point at it
    AccelOptions m_accel_options;
    int m_threads;
    std::vector<uint64_t> m_histogram;
    std::unique_ptr<RayMarcher> m_marcher;
    struct Built {
        std::unique_ptr<Accel> accel;
        uint64_t tf_version = 0;  // the TF version it holds
    };
    std::map<AccelKind, Built> m_accels;
    // The slicer and its box sources (built lazily, like the structures).
    std::unique_ptr<SliceRenderer> m_slicer;
    struct BuiltSource {
        std::unique_ptr<BoxSource> source;
        uint64_t tf_version = 0;
    };
    std::map<AccelKind, BuiltSource> m_sources;
    // A new TF (different from the last one): discretise it and hand it to the marcher; bumps
    // m_tf_version so structures, box sources and segment renderers catch up. True if it changed.
    bool update_tf(const TransferFunction& tf);
    Frame render_slice(const ViewRequest& req, int width, int height);
    // Segments: the intensity masked by the labels; with accel bitfield the label bitfield octree,
    // otherwise the intensity structure.
    std::unique_ptr<Volume> m_labels;
    LabelTable m_label_table;  // defaults (colours, 0 hidden)
    struct BuiltSegments {
        std::unique_ptr<SegmentRenderer> renderer;
        uint64_t tf_version = 0;
    };
    BuiltSegments m_segments[2];  // [0]: intensity structures, [1]: label octree
    Frame render_segments(const ViewRequest& req, int width, int height);
    bool m_has_tf = false;
    TransferFunction m_tf;
    TransferLut m_lut;
    uint64_t m_tf_version = 0;
};

}  // namespace lacuna::serve
