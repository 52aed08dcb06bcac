// 3D Slicer volume-property presets: presets.xml (MRML <VolumeProperty> elements), .vp files and
// .vp.json files (Slicer's volume-property schema v1.0.0), turned into lacuna transfer functions.
//
// What Slicer stores (all functions in data units, i.e. voxel values, VTK's conventions):
//   scalar opacity    piecewise-linear opacity over the voxel value
//   gradient opacity  piecewise-linear opacity factor over the gradient magnitude
//   colour            piecewise-linear RGB over the voxel value
//   shading           shade on/off, ambient, diffuse, specular, specular power; interpolation
//   effective range   [lo, hi]: outside it the functions are constant (optional)
// In presets.xml and .vp a function is "N v0 v1 ... v(N-1)": N numbers follow, 2 per opacity
// point (x, a) and 4 per colour point (x, r, g, b). In .vp.json each point is an object
// {x, y | color, midpoint, sharpness}.
//
// Reading follows VTK, which builds the functions point by point: points are sorted by x, and a
// point at an x already present replaces the earlier one (vtkPiecewiseFunction and
// vtkColorTransferFunction with AllowDuplicateScalars off). lacuna's TFs are piecewise linear, so
// .vp.json midpoints must be 0.5 and sharpness 0 (VTK's linear segment); anything else is
// refused rather than approximated.
//
// Conversion (to_transfer_function): domain "value" with the points unchanged; the effective
// range, when present, becomes the TF's range (the LUT is discretised over it and values outside
// clamp to its ends, which is exactly "constant outside"). Without it, the volume's visualization
// range is used, as for any value-domain TF. Shading (when shade is on) and gradient opacity
// (unless disabled) become the TF's rendering (TfRendering): defaults for the frame's features
// that the user did not set (apply_tf_rendering, lacuna/frame_spec.h).
//
// Every malformed entry is one lacuna::Error: "<file>: <entry and field>: expected ..., got ...".
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "lacuna/transfer_function.h"

namespace lacuna {

enum class SlicerInterpolation { Nearest, Linear, Cubic };
std::string to_string(SlicerInterpolation i);

// VTK / Slicer shading parameters (vtkVolumeProperty), defaults as in Slicer's schema.
struct SlicerShading {
    bool shade = false;
    float ambient = 0.1f;         // [0,1]
    float diffuse = 0.7f;         // [0,1]
    float specular = 0.2f;        // [0,1]
    float specular_power = 10.f;  // >= 0
    friend bool operator==(const SlicerShading&, const SlicerShading&) = default;
};

struct SlicerVolumeProperty {
    std::string name;  // preset name (presets.xml), file stem (.vp), "name" key or index (.vp.json)
    std::string source;  // file the entry came from
    SlicerInterpolation interpolation = SlicerInterpolation::Linear;
    SlicerShading shading;
    std::vector<OpacityPoint> scalar_opacity;    // x in data units; sorted, one point per x
    std::vector<OpacityPoint> gradient_opacity;  // x = gradient magnitude (data units per mm)
    bool gradient_opacity_enabled = true;        // .vp.json disableGradientOpacity = false
    std::vector<ColorPoint> color;               // x in data units; sorted, one point per x
    std::optional<ValueRange> effective_range;
    double scalar_opacity_unit_distance = 1.0;  // .vp.json only (presets.xml, .vp: 1)
};
std::string to_string(const SlicerVolumeProperty& p);

// Parsers of file contents; `where` is the file name used in errors. Each validates every entry.
std::vector<SlicerVolumeProperty> parse_slicer_presets_xml(const std::string& xml,
                                                           const std::string& where);
SlicerVolumeProperty parse_slicer_vp(const std::string& text, const std::string& where);
std::vector<SlicerVolumeProperty> parse_slicer_vp_json(const std::string& json,
                                                       const std::string& where);

// Reads a file by its extension (.xml, .vp, .vp.json) and returns its entries.
std::vector<SlicerVolumeProperty> load_slicer_file(const std::string& path);

// "--tf" specs naming Slicer presets:
//   slicer:FILE.xml#NAME   the VolumeProperty called NAME in a presets.xml
//   slicer:FILE.vp, FILE.vp
//   slicer:FILE.vp.json[#NAME|#INDEX], FILE.vp.json[#NAME|#INDEX]   (the only entry by default)
bool is_slicer_spec(const std::string& spec);
SlicerVolumeProperty resolve_slicer_preset(const std::string& spec);

// The lacuna TF of a Slicer property (see the header comment). Throws lacuna::Error if the
// result is not a valid TF.
TransferFunction to_transfer_function(const SlicerVolumeProperty& p);

}  // namespace lacuna
