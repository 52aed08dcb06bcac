#include "serve/tf_files.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "lacuna/error.h"
#include "transfer/slicer_presets.h"

namespace lacuna::serve {

namespace {

using nlohmann::json;

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// x in the value domain: the normalized x over [lo, hi] in the form discretise() evaluates its
// entries in, (1 - t) lo + t hi, so x = 0 and 1 land exactly on the ends.
double to_value(double x, const TransferFunction& tf, ValueRange vis) {
    if (tf.domain == TfDomain::Value) return x;
    return (1.0 - x) * double(vis.min) + x * double(vis.max);
}

// Strictly increasing x: the second point of a step moves to the next double (see the header).
template <class P>
std::vector<double> vtk_xs(const std::vector<P>& pts, const TransferFunction& tf, ValueRange vis,
                           const char* field) {
    std::vector<double> xs;
    for (const P& p : pts) {
        double x = to_value(p.x, tf, vis);
        if (!xs.empty() && x <= xs.back())
            x = std::nextafter(xs.back(), std::numeric_limits<double>::infinity());
        if (!std::isfinite(x))
            throw Error("tf", field, "a point's x is not finite in the value domain");
        xs.push_back(x);
    }
    return xs;
}

json segment(double x) {
    return json{{"x", x}, {"midpoint", 0.5}, {"sharpness", 0.0}};
}

}  // namespace

std::string to_slicer_vp_json(const TransferFunction& tf, ValueRange vis, double smallest_spacing) {
    if (tf.range) vis = *tf.range;
    json opacity = json::array(), color = json::array(), gradient = json::array();
    const std::vector<double> ox = vtk_xs(tf.opacity, tf, vis, "opacity");
    for (size_t i = 0; i < ox.size(); ++i) {
        json p = segment(ox[i]);
        p["y"] = double(tf.opacity[i].a);
        opacity.push_back(p);
    }
    const std::vector<double> cx = vtk_xs(tf.color, tf, vis, "color");
    for (size_t i = 0; i < cx.size(); ++i) {
        json p = segment(cx[i]);
        const ColorPoint& c = tf.color[i];
        p["color"] = json::array({double(c.r), double(c.g), double(c.b)});
        color.push_back(p);
    }
    // Gradient opacity is over |grad| in both (never normalized).
    const TfRendering& r = tf.rendering;
    const bool has_gradient = !r.gradient_opacity.empty();
    if (has_gradient) {
        TransferFunction as_value;
        as_value.domain = TfDomain::Value;
        const std::vector<double> gx =
            vtk_xs(r.gradient_opacity, as_value, vis, "gradient_opacity");
        for (size_t i = 0; i < gx.size(); ++i) {
            json p = segment(gx[i]);
            p["y"] = double(r.gradient_opacity[i].a);
            gradient.push_back(p);
        }
    } else {
        json p = segment(0.0);
        p["y"] = 1.0;
        gradient.push_back(p);  // VTK's constant 1, disabled below
    }
    const TfShading shading = r.shading.value_or(TfShading{});
    json component{{"componentWeight", 1.0},
                   {"shade", r.shading.has_value()},
                   {"lighting",
                    {{"ambient", double(shading.ambient)},
                     {"diffuse", double(shading.diffuse)},
                     {"specular", double(shading.specular)},
                     {"specularPower", double(shading.specular_power)}}},
                   {"disableGradientOpacity", !has_gradient},
                   {"scalarOpacityUnitDistance", smallest_spacing > 0 ? smallest_spacing : 1.0},
                   {"scalarOpacity", {{"points", opacity}}},
                   {"gradientOpacity", {{"points", gradient}}},
                   {"rgbTransferFunction", {{"points", color}}}};
    json property{{"interpolationType", "linear"},
                  {"independentComponents", false},
                  {"components", json::array({component})}};
    if (!tf.name.empty()) property["name"] = tf.name;
    if (tf.range)
        property["effectiveRange"] = json::array({double(tf.range->min), double(tf.range->max)});
    json doc{{"@schema",
              "https://raw.githubusercontent.com/Slicer/Slicer/main/Modules/Loadable/"
              "VolumeRendering/Resources/Schema/volume-property-schema-v1.0.0.json#"},
             {"volumeProperties", json::array({property})}};
    return doc.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

TransferFunction read_tf_file(const std::string& name, const std::string& text) {
    const std::string where = name.empty() ? "upload" : name;
    bool slicer_json = ends_with(name, ".vp.json");
    if (!slicer_json && !ends_with(name, ".vp")) {
        // A .json that is a Slicer document all the same.
        const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
        slicer_json = j.is_object() && j.contains("volumeProperties");
    }
    if (slicer_json) {
        const std::vector<SlicerVolumeProperty> all = parse_slicer_vp_json(text, where);
        if (all.size() != 1) {
            std::string names;
            for (const auto& p : all) names += (names.empty() ? "" : ", ") + p.name;
            throw Error(where, "volumeProperties",
                        "expected one volume property to load, the file holds " +
                            std::to_string(all.size()) + " (" + names + ")");
        }
        return to_transfer_function(all[0]);
    }
    if (ends_with(name, ".vp")) return to_transfer_function(parse_slicer_vp(text, where));
    return parse_transfer_function(text, where);
}

}  // namespace lacuna::serve
