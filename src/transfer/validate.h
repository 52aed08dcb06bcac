// Structural checks of an in-memory TransferFunction, shared by the JSON reader (after it has
// turned the document into a struct), discretise(), lerp() and to_json().
#pragma once
#include <string>

#include "lacuna/transfer_function.h"

namespace lacuna::tf_detail {

// Throws lacuna::Error(where, field, what) for the first violation, checked in this order:
//   color, opacity       non-empty
//   color[i], opacity[i] finite x; r, g, b, a in [0,1]; x sorted ascending, at most two
//                        points per x (a step); for TfDomain::Normalized x in [0,1]
//   range                finite min < max (when set)
//   shading              ambient, diffuse, specular in [0,1], finite specular_power >= 0
//   gradient_opacity[i]  as opacity[i] (value domain) with x >= 0 (a gradient magnitude)
void validate(const TransferFunction& tf, const std::string& where);

// {"ambient": .., "diffuse": .., "specular": .., "specular_power": ..}, as JSON writes it.
std::string shading_text(const TfShading& s);

// The text of one point as the JSON format writes it: "[x, r, g, b]" or "[x, a]".
std::string point_text(const ColorPoint& p);
std::string point_text(const OpacityPoint& p);

}  // namespace lacuna::tf_detail
