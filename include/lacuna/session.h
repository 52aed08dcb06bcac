// Session: the one place that wires volume -> TF -> structure -> renderer -> pixels
// (STYLE.md habit 11). Every front end (the CLI's render command, the viewer's frame renderer)
// builds a FrameSpec (lacuna/frame_spec.h) and calls render(); none of them holds a structure or
// a renderer of its own.
//
// What it owns and why that keeps frames exact and cheap:
//   - the volume (and a label volume for the segment renderer), at a stable address: structures
//     and renderers point into them;
//   - the TF (and an optional back TF), discretised once per change into the LUT every renderer
//     and structure shares (ValueToLut, lacuna/transfer_function.h);
//   - the structures, box sources and segment renderers, built lazily the first time a frame
//     asks for one and kept for the next frames. Each remembers the TF version it holds; a frame
//     first brings the one it uses up to the current TF (a structure not used in between never
//     pays for TF changes). A structure therefore always holds the LUT of the frame's TF (or the
//     union of both TFs with two_tfs) when it is rendered through, which is the exactness
//     condition of every skipping structure: the image is the `none` image byte for byte.
//
// refine() computes the finer per-TF level of the built structures (Accel::refine): a front end
// calls it after a TF change, off the frame's critical path (the CLI before its frame, the viewer
// when its render thread is idle). Not thread-safe: one thread renders through a session.
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/frame_spec.h"
#include "lacuna/image.h"
#include "lacuna/renderer.h"
#include "lacuna/segments.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

class BoxSource;  // src/slice/box_source.h

// The slicer's counters (src/slice/slice_renderer.h SliceStats), for the front ends' reports.
struct SlicerFrameStats {
    uint64_t boxes = 0, polygons = 0;
    double setup_fraction = 0, setup_cpu_fraction = 0;  // polygon set-up share of wall / CPU time
    int map_updates = 0, desired_updates = 0;
    uint64_t boxes_culled = 0, boxes_clipped = 0;
    double skipped_fraction = 0, culled_fraction = 0, clipped_fraction = 0;
    double occlusion_seconds = 0;
    double voxels = 0;  // cells in the frame's boxes (the box source's non-empty cells)
};

struct FrameResult {
    Image image;
    std::vector<uint32_t> sample_counts;  // per pixel, when FrameSpec::count_samples
    // Per pixel premultiplied RGBA before the background and the 8-bit rounding (the renderer's
    // values: image = round(clamp(rgb + (1 - a) * background) * 255)), when FrameSpec::keep_float.
    std::vector<float> rgba_float;
    RenderStats stats;  // the slicer fills seconds, samples, pixels
    // What this frame did besides rendering.
    double build_seconds = 0;    // built the frame's structure (0: it was built before)
    double tf_sync_seconds = 0;  // brought the structure to the current TF (0: it held it)
    // The frame's structure (ray marcher, or the segment renderer's intensity structure).
    std::optional<AccelStats> structure;
    std::optional<SegmentStats> segments;  // the segment renderer's label octree
    std::optional<SlicerFrameStats> slicer;
};

class Session {
  public:
    // threads: render and build threads (0 = all hardware threads).
    explicit Session(Volume volume, int threads = 0);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    const Volume& volume() const { return *m_volume; }
    int threads() const { return m_threads; }
    // World box of the volume (what the orbit camera frames).
    Box3f bounds() const;

    // ---- Transfer functions: every change goes through here.
    // Sets the TF; false (and nothing done) when it equals the current one.
    bool set_transfer_function(const TransferFunction& tf);
    // The TF behind clip plane 0 for frames with two_tfs; nullopt removes it.
    void set_back_transfer_function(const std::optional<TransferFunction>& tf);
    bool has_transfer_function() const { return m_has_tf; }
    const TransferFunction& transfer_function() const { return m_tf; }
    const TransferLut& lut() const { return m_lut; }

    // ---- Labels for the segment renderer. Throws lacuna::Error if `labels` cannot be a label
    // map of this volume. Without labels, labels mode reads the volume itself as the label map.
    void set_labels(Volume labels);
    bool has_labels() const { return m_labels != nullptr; }
    // The label map the segment renderer reads: the label volume, else the volume itself.
    const Volume& label_volume() const { return m_labels ? *m_labels : *m_volume; }
    // The default table of the label map (colours, label 0 hidden).
    const LabelTable& label_table() const;

    // ---- Distributed rendering (src/dist/, docs/distributed.md): the session's volume is a
    // brick of a larger grid (BrickOwnership, lacuna/renderer.h); `whole_bounds` is the whole
    // grid's world box, which the camera frames. Ray-marcher frames then take only the brick's
    // owned samples, without early termination; other renderers and features are refused.
    void set_brick(const BrickOwnership& brick, const Box3f& whole_bounds);
    const std::optional<BrickOwnership>& brick() const { return m_brick; }

    // ---- Frames.
    // The camera of a spec (the orbit around bounds(), then the pan).
    Camera camera(const FrameSpec& spec) const;
    // Builds what the frame needs and brings it to the current TF, without rendering (a front end
    // times a build, or calls refine() before its first frame). Validates the spec.
    FrameResult prepare(const FrameSpec& spec);
    FrameResult render(const FrameSpec& spec);
    // The finer per-TF level of every built structure (see above).
    void refine();
    // Releases every built structure, box source and segment renderer (they rebuild lazily).
    void drop_structures();
    // How many structures, box sources and segment renderers are built (tests, reports).
    size_t built_count() const;
    // What frames of `spec` render through, as built (nullptr: not built yet, or the spec's
    // renderer does not use one): for reports and tests that look inside a structure (the
    // benches' kd-tree list, the growing boxes' build phases). Rendering never needs them.
    const Accel* built_structure(const FrameSpec& spec) const;
    const BoxSource* built_box_source(const FrameSpec& spec) const;

  private:
    void check_tfs(const FrameSpec& spec) const;
    // prepare()'s part for each renderer, and the intensity structure two of them share.
    void prepare_marcher(const FrameSpec& spec, FrameResult& out);
    void prepare_slicer(const FrameSpec& spec, FrameResult& out);
    void prepare_segments(const FrameSpec& spec, FrameResult& out);
    Accel& intensity_structure(const FrameSpec& spec, FrameResult& out);

    std::unique_ptr<Volume> m_volume;  // stable address: structures and renderers point at it
    std::unique_ptr<Volume> m_labels;
    mutable std::optional<LabelTable> m_label_table;  // made on first use (it scans the labels)
    int m_threads = 0;
    bool m_has_tf = false;
    TransferFunction m_tf;
    TransferLut m_lut;
    std::optional<TransferLut> m_back_lut;
    uint64_t m_tf_version = 0;  // bumped by every TF change (front or back)
    std::optional<BrickOwnership> m_brick;
    Box3f m_whole_bounds{};
    // The renderers and the lazily built structures (src/session/session.cpp).
    struct State;
    std::unique_ptr<State> m_state;
};

}  // namespace lacuna
