// Transfer functions: piecewise-linear colour and opacity over the visualization range,
// discretised to a lookup table (LUT). JSON format: docs/transfer-functions.md.
//
// Value -> LUT entry mapping (one definition, used by the renderers AND the skipping
// structures, so both agree on which entry a sample reads):
//     u   = (v - vis.min) * (size-1) / (vis.max - vis.min)
//     idx = clamp(int(u + 0.5), 0, size-1)
// The map is monotone in v, so every sample whose value lies in [lo, hi] reads an entry in
// [idx(lo), idx(hi)]: that is what makes per-cell value ranges sufficient for exact skipping.
//
// The map is total: every sample gets an entry in [0, size-1], never NaN and never int(NaN).
// The argument, which keeps the per-sample code at a subtract, a multiply, an add and a clamp:
//   1. samples are finite: Volume::compute_range rejects NaN/Inf float voxels and float data
//      whose max - min overflows float, so no lerp of two voxels meets inf - inf or 0 * inf;
//   2. offset() is finite and scale() is finite and > 0 for ANY range and size (the
//      constructor below; ranges the boundaries let through always give the exact formula);
//   3. so (v - offset) * scale + 0.5 is finite or +-inf (an overflow), never NaN, and the clamp
//      puts +-inf at the ends. Every kernel evaluates the same three operations and clamp.
// The boundaries (discretise(), Volume::set_vis_range, the TF JSON "range") reject the ranges
// whose scale float cannot hold (check_lut_range) with one line naming the range.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lacuna/volume.h"

namespace lacuna {

inline constexpr int kDefaultLutSize = 1024;

// Where control point positions x live.
enum class TfDomain {
    Normalized,  // x in [0,1] across the volume's visualization range (portable presets)
    Value,       // x in voxel values (like VTK / 3D Slicer)
};
std::string to_string(TfDomain d);  // "normalized" / "value", as in the JSON format

// Two points with equal x form a step: the TF takes the first one's value just left of x and
// the second one's value at x and to its right (at most two points may share an x).
struct ColorPoint {
    double x = 0;
    float r = 0, g = 0, b = 0;  // linear RGB in [0,1]
    friend bool operator==(const ColorPoint&, const ColorPoint&) = default;
};
struct OpacityPoint {
    double x = 0;
    float a = 0;  // opacity per unit sample distance (one voxel of the smallest spacing), [0,1]
    friend bool operator==(const OpacityPoint&, const OpacityPoint&) = default;
};

// How a frame shows the volume's values after the TF (lacuna/renderer.h runs it; declared here
// because a TF file may ask for one, TfRendering below).
enum class BlendMode {
    Composite,  // front-to-back emission-absorption (default)
    Mip,        // TF colour and opacity of the largest sample value on the ray
    MinIp,      // ... of the smallest sample value
    Average,    // ... of the mean value of the samples with non-zero TF opacity
};
std::string to_string(BlendMode m);

// Blinn-Phong terms as 3D Slicer's volume property holds them (vtkVolumeProperty: ambient,
// diffuse, specular, specular power), mapped one to one onto lacuna's PhongParams.
struct TfShading {
    float ambient = 0.1f, diffuse = 0.7f, specular = 0.2f, specular_power = 10.f;
    friend bool operator==(const TfShading&, const TfShading&) = default;
};

// The rendering a TF was made for, when its source says (3D Slicer's presets carry shading and a
// gradient opacity beside their functions; the MIP presets want MIP). None of it changes the
// LUT: a front end applies it to the frame's features the user did not set
// (apply_tf_rendering, lacuna/frame_spec.h; the rule is in docs/transfer-functions.md).
struct TfRendering {
    std::optional<TfShading> shading;  // Phong with these terms; nullopt: unshaded
    // Opacity factor over the gradient magnitude |grad| (voxel values per mm), piecewise linear
    // as the TF's opacity (x sorted, a in [0,1], at most two points per x); empty: none.
    std::vector<OpacityPoint> gradient_opacity;
    std::optional<BlendMode> blend;  // nullopt: the frame's (composite by default)
    bool empty() const { return !shading && gradient_opacity.empty() && !blend; }
    friend bool operator==(const TfRendering&, const TfRendering&) = default;
};

struct TransferFunction {
    std::string name;
    TfDomain domain = TfDomain::Normalized;
    std::vector<ColorPoint> color;      // sorted by x, at least one point
    std::vector<OpacityPoint> opacity;  // sorted by x, at least one point
    // Optional visualization range carried by the TF file (values); overrides the volume's.
    std::optional<ValueRange> range;
    // What the TF's file asks of the frame (JSON keys "shading", "gradient_opacity", "blend").
    TfRendering rendering;
};
std::string to_string(const TransferFunction& tf);
// Exact equality of every field (the JSON round trip is exact).
bool operator==(const TransferFunction& a, const TransferFunction& b);
// GoogleTest prints a TransferFunction through this (found by ADL).
void PrintTo(const TransferFunction& tf, std::ostream* os);

// Linear interpolation of two TFs with the same domain (bitfield paper, Section 4.5: the TF
// animation). Control points are merged at the union of both x sets. w in [0,1]. The result
// carries a's rendering (a TF animation keeps the look it starts with).
TransferFunction lerp(const TransferFunction& a, const TransferFunction& b, float w);

// RGBA per LUT entry; colour straight (not premultiplied), alpha per unit distance.
struct Rgba {
    float r = 0, g = 0, b = 0, a = 0;
    friend bool operator==(const Rgba&, const Rgba&) = default;
};
std::string to_string(const Rgba& c);

// Ranges the map resolves with its exact formula: finite min < max and a finite scale
// (size-1)/(max-min), i.e. a width of at least (size-1)/FLT_MAX (~3e-36 for 1024 entries).
// Widths beyond FLT_MAX (e.g. [-3e38, 3e38]) are fine: the scale is taken from the exact width.
bool lut_range_ok(ValueRange vis, int size = kDefaultLutSize);
// Throws lacuna::Error(where, field, ...) naming the range and the narrowest width when
// !lut_range_ok(vis, size).
void check_lut_range(ValueRange vis, int size, const std::string& where, const std::string& field);

class ValueToLut {
  public:
    ValueToLut() = default;
    // For a range with lut_range_ok: the exact map, bit for bit the formula in the header
    // comment. Otherwise (a range no boundary accepts) still total and monotone: a non-finite
    // min reads as 0, and a scale float cannot hold becomes FLT_MAX (a step at min, the limit
    // of an ever narrower range).
    ValueToLut(ValueRange vis, int size)
        : m_min(std::isfinite(vis.min) ? vis.min : 0.f), m_last(size > 1 ? size - 1 : 0) {
        float s = float(m_last) / (vis.max - vis.min);
        // A finite range wider than float (max - min overflowed): the width in double.
        if (std::isinf(vis.max - vis.min) && std::isfinite(vis.min) && std::isfinite(vis.max))
            s = std::max(float(double(m_last) / (double(vis.max) - double(vis.min))),
                         std::numeric_limits<float>::min());
        m_scale = s > 0.f && s <= std::numeric_limits<float>::max()
                      ? s
                      : std::numeric_limits<float>::max();
    }
    int operator()(float v) const {
        float u = (v - m_min) * m_scale + 0.5f;
        u = u < 0.f ? 0.f : (u > float(m_last) ? float(m_last) : u);
        return int(u);
    }
    int size() const { return m_last + 1; }
    // The affine map's terms, for kernels that evaluate operator() several lanes at a time.
    float offset() const { return m_min; }
    float scale() const { return m_scale; }
    int last() const { return m_last; }

  private:
    float m_min = 0, m_scale = 1;
    int m_last = 0;
};

struct TransferLut {
    std::vector<Rgba> entries;
    ValueRange vis;  // the range this LUT was discretised over
    ValueToLut map() const { return ValueToLut(vis, int(entries.size())); }
    int size() const { return int(entries.size()); }
};

// Discretises tf over `vis` (tf.range, when set, wins) into `size` entries: entry e holds the
// piecewise-linear TF evaluated at the value vis.min + e*(vis.max-vis.min)/(size-1).
TransferLut discretise(const TransferFunction& tf, ValueRange vis, int size = kDefaultLutSize);

// Built-in presets: lacuna's own in the normalized domain (ct-bone, ct-skin, ct-soft-tissue,
// mr-default, mr-skin, mr-brain, mr-gap, label-band) and 3D Slicer's in the value domain with
// their shading, gradient opacity and blend (CT-AAA, CT-Bone, CT-Lung, CT-Soft-Tissue, CT-MIP,
// MR-Default, MR-Angio, MR-MIP; src/transfer/presets.cpp). Throws lacuna::Error listing the
// valid names for an unknown one.
TransferFunction preset(const std::string& name);
std::vector<std::string> preset_names();

// JSON (docs/transfer-functions.md). `where` is the file name used in error messages.
TransferFunction parse_transfer_function(const std::string& json_text, const std::string& where);
TransferFunction load_transfer_function(const std::string& path);
std::string to_json(const TransferFunction& tf);

// "--tf" argument: a preset name, or a path to a .json file.
TransferFunction resolve_transfer_function(const std::string& spec);

}  // namespace lacuna
