// The viewer's TF files (docs/viewer.md, "Saving work"): what the page's TF download, Slicer
// export and upload buttons turn into text and back, through the library's own readers.
//
//   lacuna TF JSON   to_json(TransferFunction) (docs/transfer-functions.md): what `lacuna render
//                    --tf FILE.json` reads; its round trip is exact.
//   Slicer .vp.json  3D Slicer's volume-property schema v1.0.0, one volumeProperty, as
//                    src/transfer/slicer_presets.h reads it (`lacuna render --tf FILE.vp.json`).
//
// Writing .vp.json. Slicer's functions live in voxel values, so a normalized TF's x become
// lo + x (hi - lo) over [lo, hi] = the TF's range when it has one, else the volume's
// visualization range (the range its LUT is discretised over): the same TF, up to the rounding
// of that affine map in double. The TF's own range (when set) is the effectiveRange, read back as
// the TF's range. Points are written as VTK segments that are linear (midpoint 0.5, sharpness
// 0), the only kind the reader takes. Two points at one x (a step) cannot both be held by a VTK
// function (a point at an x already present replaces the earlier one), so the second is written
// at the next double above x: the function differs from the step only on (x, nextafter(x)), an
// interval no LUT entry falls in unless one sits exactly on x. The rendering the TF carries
// (lacuna/transfer_function.h TfRendering) becomes Slicer's shade flag and lighting terms and its
// gradient opacity; a TF without gradient opacity is written with disableGradientOpacity
// (and the constant 1 VTK expects), which the reader drops again. A blend mode (MIP) is not part
// of a Slicer volume property and is not written. scalarOpacityUnitDistance is the volume's
// smallest voxel spacing: lacuna's opacity is per sample distance of one smallest spacing, so
// Slicer, which scales opacity per that distance in mm, shows the same opacity.
//
// Reading (upload): a name ending in .vp.json, or a document with "volumeProperties", is a Slicer
// .vp.json (it must hold one property, or the first is not silently picked); a name ending in .vp
// is a Slicer .vp; anything else is lacuna TF JSON. Errors are the readers' own one-line
// lacuna::Error naming the file and the field.
#pragma once
#include <string>

#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::serve {

// The .vp.json document of `tf` over `vis` (the volume's visualization range; tf.range wins),
// with scalarOpacityUnitDistance = smallest_spacing (mm). Throws lacuna::Error when the result
// would not read back (a non-finite x after the conversion).
std::string to_slicer_vp_json(const TransferFunction& tf, ValueRange vis, double smallest_spacing);

// An uploaded TF file's text, by its name (see the header comment).
TransferFunction read_tf_file(const std::string& name, const std::string& text);

}  // namespace lacuna::serve
