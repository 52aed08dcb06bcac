// The viewer's renderer: turns a ViewRequest into a FrameSpec (lacuna/frame_spec.h) and renders
// it through a lacuna::Session, which owns the volume, the TF and the lazily built structures;
// adds the numbers the page's overlay shows. Not thread-safe: the server calls it from one render
// thread.
//
// For the same settings a frame is the image `lacuna render` writes (tested): the camera is
// Camera::orbit with the request's azimuth, elevation and zoom (fov 30, perspective), ert 0.99 or
// off, black background.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/frame_spec.h"
#include "lacuna/renderer.h"
#include "lacuna/segments.h"
#include "lacuna/session.h"
#include "lacuna/volume.h"
#include "serve/protocol.h"

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

// Where the frames come from when not from the renderer's own session: under `mpirun -np N
// lacuna serve` every rank renders its brick of each frame (apps/lacuna/serve_mpi.cpp over
// src/dist/). The renderer's session still answers slices and probes, holds the histogram and
// counts the reference lattice; the source renders the frames and refines its structures.
class FrameSource {
  public:
    virtual ~FrameSource() = default;
    // The frame of `spec` under `tf` (Error for one the source cannot render: the page's error
    // message).
    virtual FrameResult render(const TransferFunction& tf, const FrameSpec& spec) = 0;
    virtual void refine() = 0;
};

class FrameRenderer {
  public:
    // threads: render and build threads (0 = all). The renderer keeps the volume.
    FrameRenderer(Volume volume, const AccelOptions& accel_options = {}, int threads = 0);
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    const Volume& volume() const { return m_session->volume(); }
    // A label volume (same dims) for the page's segments toggle (docs/segments.md). Throws
    // lacuna::Error if it cannot be a label map of this volume.
    void set_labels(Volume labels);
    // Replaces the volume (another volume of a 4D file: the viewer's frame selector): a fresh
    // session (its structures rebuild lazily), the label volume kept, the histogram recomputed.
    // Throws lacuna::Error, keeping the old volume, if the labels cannot label the new one. Not
    // thread-safe against anything: the server calls it with the render thread locked out.
    void set_volume(Volume volume);
    int label_count() const {
        return m_session->has_labels() ? m_session->label_table().size() : 0;
    }
    // Voxel counts in kHistogramBins equal bins over the visualization range.
    static constexpr int kHistogramBins = 256;
    const std::vector<uint64_t>& histogram() const { return m_histogram; }

    // Frames from `source` from now on (nullptr: from the session again).
    void set_frame_source(std::unique_ptr<FrameSource> source) { m_source = std::move(source); }

    // Renders `req` at width x height (the server passes a reduced size for previews).
    Frame render(const ViewRequest& req, int width, int height);
    // Computes the built structures' finer per-TF level (Accel::refine) for the current TF:
    // the server calls it when the render thread is idle, after a frame went out, so a TF edit
    // never waits for it and the frames after it use it.
    void refine();

    // A slice pane's picture (lacuna/mpr.h): the slice at window/level, the label overlay when
    // asked; its geometry for the header. Thread-safe against render(): it reads only the
    // volume, the label volume and its table, which are fixed once the server runs (the server
    // answers slices on its network thread). Throws lacuna::Error("slice", field, ...), e.g.
    // "overlay_opacity" without a label volume.
    struct SliceImage {
        Image image;
        SliceGeometry geometry;
        bool overlay = false;
        double seconds = 0;
    };
    SliceImage slice(const SliceRequest& req, int max_side) const;
    ProbeResult probe(const ProbeRequest& req) const;

    // The frame a request describes, at width x height.
    FrameSpec frame_spec(const ViewRequest& req, int width, int height) const;
    // The other way (a session file opened in the page): the request whose frame_spec() is
    // `f` when the page can express it, its size f.width x f.height, its TF `tf`. Throws
    // lacuna::Error("session", "frame.<field>", ...) for what the page has no control for (the
    // segment renderer, a structure outside accel_names()); the caller compares frame_spec()
    // of the result with `f` for everything else (a field the mapping does not carry differs).
    ViewRequest view_request(const FrameSpec& f, const TransferFunction& tf) const;

  private:
    std::unique_ptr<Session> m_session;
    AccelOptions m_accel_options;  // the structures' parameters (--leaf, --bits of `lacuna serve`)
    int m_threads;
    std::vector<uint64_t> m_histogram;
    std::unique_ptr<FrameSource> m_source;
};

}  // namespace lacuna::serve
