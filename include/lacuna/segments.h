// Segment visibility (the bitfield paper's Section 6 future work: label bitfields of 128 bits or
// more per node): a label volume with per-label colour, opacity and visibility, rendered by the
// ray marcher's lattice and skipped through a label bitfield octree.
//
// Two modes, as in 3D Slicer's segmentations and VTK's label maps:
//   Labels   the label volume alone: each sample takes its label's colour and opacity.
//   Masked   an intensity volume through its TF, masked by the labels: a sample is composited
//            only where its label is visible; its opacity is the TF's times the label's
//            opacity, its colour the TF's mixed with the label's by `tint` (0 = the TF's).
// Labels are never interpolated: a sample reads the label of the nearest voxel (round to
// nearest in index space), which is one of the 8 corners of its trilinear cell. That is what
// makes a per-cell label set (the labels of the 8 corners) exact for skipping, just as the
// per-cell value range is for intensities.
//
// Toggling a label changes one bit of the visibility mask the octree is tested against: no
// rebuild (SegmentRenderer::set_labels is O(number of labels)).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/renderer.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna {

// Label values are 0..kMaxLabel (uint8, uint16, or non-negative int16 voxels).
inline constexpr int kMaxLabel = 65535;

struct LabelStyle {
    std::string name;
    float r = 1, g = 1, b = 1;  // linear RGB in [0,1]
    float opacity = 1;          // labels mode: per unit distance; masked mode: a factor
    bool visible = true;
};

// One style per label value 0..size()-1. Value 0 is the background and hidden by default.
struct LabelTable {
    std::vector<LabelStyle> styles;
    int size() const { return int(styles.size()); }
};

// Checks that `labels` can be a label map (integer type, values in 0..kMaxLabel) and, when
// `intensity` is given, has its dimensions. Throws lacuna::Error(where, ...).
void check_label_volume(const Volume& labels, const Volume* intensity, const std::string& where);
// One past the largest voxel value of a label map (scans the voxels).
int label_count(const Volume& labels);
// Distinct colours (golden-ratio hues), every label but 0 visible, for labels 0..max value.
LabelTable default_label_table(const Volume& labels);
// Styles from a file over the default table: our JSON (docs/segments.md) or an MRIcron colour
// table (.lut: 768 bytes, 256 reds then greens then blues; names from NAME.txt beside it, as in
// Debian's mricron-data). Throws lacuna::Error(path, field, expected).
LabelTable load_label_table(const std::string& path, const Volume& labels);
// "all", "none", or a comma-separated list of labels and ranges ("1,2,37-40"): sets those
// labels' visibility. Throws lacuna::Error(where, "labels", ...) on a malformed list.
void set_label_visibility(LabelTable& table, const std::string& spec, bool visible,
                          const std::string& where);

enum class SegmentMode { Labels, Masked };
std::string to_string(SegmentMode m);
SegmentMode parse_segment_mode(const std::string& s, const std::string& where = "segments.mode");

struct SegmentOptions {
    SegmentMode mode = SegmentMode::Masked;
    bool skip = true;        // use the label bitfield octree (false: march every sample)
    int leaf_cells = 8;      // octree leaf edge in cells (power of two, 2..64)
    int bitfield_bits = 64;  // masked mode: the intensity bitfield's width
    float tint = 0.f;        // masked mode: weight of the label colour against the TF colour
};

struct SegmentStats {
    double build_seconds = 0;         // label octree (+ intensity bitfield) build
    double label_update_seconds = 0;  // last set_labels: the visibility change
    size_t bytes = 0;                 // octree memory
    int label_words = 0;              // 64-bit words per node (labels rounded up to 64)
};

// Renders an intensity volume masked by labels, or a label volume alone, on the ray marcher's
// sample lattice (include/lacuna/renderer.h). RenderOptions' step, ert, threads, background,
// count_samples and keep_float apply. Volumes must outlive the renderer.
class SegmentRenderer {
  public:
    // intensity may be null in Labels mode. Builds the octree when options.skip.
    SegmentRenderer(const Volume* intensity, const Volume& labels, const SegmentOptions& options);
    ~SegmentRenderer();
    SegmentRenderer(const SegmentRenderer&) = delete;
    SegmentRenderer& operator=(const SegmentRenderer&) = delete;
    // Masked mode: the intensity TF (updates the octree's TF bitfield).
    void set_transfer_function(const TransferLut& lut);
    // Colours, opacities, visibility. Costs O(labels): no rebuild.
    void set_labels(const LabelTable& table);
    // Mask mode without the label octree (options.skip == false): skip through any intensity
    // structure instead (it must hold the current TF; nullptr: march every sample). Exact: it only
    // drops samples whose TF opacity is zero, which the mask cannot raise.
    void set_accel(const Accel* accel);
    RenderResult render(const Camera& camera, const RenderOptions& options) const;
    Box3f bounds() const;
    const SegmentStats& stats() const { return m_stats; }

  private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
    SegmentStats m_stats;
};

}  // namespace lacuna
