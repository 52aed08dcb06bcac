// Transfer function core: validation, evaluation into a LUT, interpolation of two TFs, text.
#include "lacuna/transfer_function.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "lacuna/error.h"
#include "transfer/number_text.h"
#include "transfer/piecewise.h"
#include "transfer/validate.h"

namespace lacuna {

namespace tf_detail {

// Built with += rather than "[" + ...: GCC 12 at -O3 warns falsely (-Wrestrict) on the latter.
std::string point_text(const ColorPoint& p) {
    std::string s = "[";
    s += double_text(p.x);
    for (float v : {p.r, p.g, p.b}) s += ", " + float_text(v);
    return s += "]";
}
std::string point_text(const OpacityPoint& p) {
    std::string s = "[";
    s += double_text(p.x);
    s += ", " + float_text(p.a);
    return s += "]";
}

namespace {

// False for NaN, so one check covers both.
bool unit(float v) {
    return v >= 0.f && v <= 1.f;
}
bool values_in_unit(const ColorPoint& p) {
    return unit(p.r) && unit(p.g) && unit(p.b);
}
bool values_in_unit(const OpacityPoint& p) {
    return unit(p.a);
}

// `shape` is the expected form, e.g. "[x, a] with a in [0,1]".
template <class P>
void validate_points(const std::vector<P>& pts, TfDomain domain, const std::string& where,
                     const std::string& name, const std::string& shape) {
    if (pts.empty())
        throw Error(where, name, "expected at least one control point " + shape + ", got none");
    for (size_t i = 0; i < pts.size(); ++i) {
        const P& p = pts[i];
        const std::string field = name + "[" + std::to_string(i) + "]";
        if (!std::isfinite(p.x) || !values_in_unit(p))
            throw Error(where, field, "expected " + shape + " and finite x, got " + point_text(p));
        if (domain == TfDomain::Normalized && !(p.x >= 0.0 && p.x <= 1.0))
            throw Error(where, field,
                        "expected x in [0,1] for domain \"normalized\", got " + point_text(p));
        if (i == 0) continue;
        if (p.x < pts[i - 1].x)
            throw Error(where, field,
                        "expected x >= " + double_text(pts[i - 1].x) +
                            " (control points sorted by x), got " + point_text(p));
        if (i >= 2 && p.x == pts[i - 2].x)
            throw Error(
                where, field,
                "at most two points may share x = " + double_text(p.x) + " (a step), got a third");
    }
}

}  // namespace

void validate(const TransferFunction& tf, const std::string& where) {
    validate_points(tf.color, tf.domain, where, "color", "[x, r, g, b] with r, g, b in [0,1]");
    validate_points(tf.opacity, tf.domain, where, "opacity", "[x, a] with a in [0,1]");
    if (tf.range) check_lut_range(*tf.range, kDefaultLutSize, where, "range");
    const TfRendering& r = tf.rendering;
    if (r.shading) {
        const TfShading& s = *r.shading;
        if (!(unit(s.ambient) && unit(s.diffuse) && unit(s.specular)) ||
            !(s.specular_power >= 0.f && std::isfinite(s.specular_power)))
            throw Error(where, "shading",
                        "expected ambient, diffuse, specular in [0,1] and a finite specular_power "
                        ">= 0, got " +
                            shading_text(s));
    }
    if (!r.gradient_opacity.empty()) {
        // Its x is a gradient magnitude (values per mm) whatever the TF's domain: >= 0.
        validate_points(r.gradient_opacity, TfDomain::Value, where, "gradient_opacity",
                        "[x, a] with a in [0,1]");
        for (size_t i = 0; i < r.gradient_opacity.size(); ++i)
            if (!(r.gradient_opacity[i].x >= 0.0))
                throw Error(where, "gradient_opacity[" + std::to_string(i) + "]",
                            "expected x >= 0 (a gradient magnitude), got " +
                                point_text(r.gradient_opacity[i]));
    }
}

std::string shading_text(const TfShading& s) {
    return "{\"ambient\": " + float_text(s.ambient) + ", \"diffuse\": " + float_text(s.diffuse) +
           ", \"specular\": " + float_text(s.specular) +
           ", \"specular_power\": " + float_text(s.specular_power) + "}";
}

}  // namespace tf_detail

bool lut_range_ok(ValueRange vis, int size) {
    if (size < 2 || !(std::isfinite(vis.min) && std::isfinite(vis.max) && vis.min < vis.max))
        return false;
    // max - min overflowing is fine (ValueToLut takes the width in double then); a scale
    // beyond float is not.
    const float w = vis.max - vis.min;
    return std::isinf(w) || std::isfinite(float(size - 1) / w);
}

void check_lut_range(ValueRange vis, int size, const std::string& where, const std::string& field) {
    using tf_detail::float_text;
    if (lut_range_ok(vis, size)) return;
    const std::string got = "[" + float_text(vis.min) + ", " + float_text(vis.max) + "]";
    if (!(std::isfinite(vis.min) && std::isfinite(vis.max) && vis.min < vis.max))
        throw Error(where, field, "expected [min, max] with finite min < max, got " + got);
    // The narrowest width whose scale (size-1)/width float holds.
    char narrowest[32];
    std::snprintf(narrowest, sizeof(narrowest), "%.3g",
                  double(size - 1) / double(std::numeric_limits<float>::max()));
    throw Error(where, field,
                "expected a range at least " + std::string(narrowest) +
                    " wide (narrower ones overflow the " + std::to_string(size) +
                    "-entry LUT's float scale), got " + got);
}

namespace {

std::string tf_where(const TransferFunction& tf) {
    return tf.name.empty() ? std::string("transfer function")
                           : "transfer function '" + tf.name + "'";
}

}  // namespace

std::string to_string(BlendMode m) {
    switch (m) {
        case BlendMode::Composite:
            return "composite";
        case BlendMode::Mip:
            return "mip";
        case BlendMode::MinIp:
            return "minip";
        case BlendMode::Average:
            return "average";
    }
    return "?";
}

std::string to_string(TfDomain d) {
    return d == TfDomain::Normalized ? "normalized" : "value";
}

std::string to_string(const Rgba& c) {
    using tf_detail::float_text;
    return "Rgba{" + float_text(c.r) + ", " + float_text(c.g) + ", " + float_text(c.b) + ", " +
           float_text(c.a) + "}";
}

std::string to_string(const TransferFunction& tf) {
    using namespace tf_detail;
    std::string s = "TransferFunction{name=\"" + tf.name + "\", domain=" + to_string(tf.domain);
    s += ", range=";
    if (tf.range) {
        s += "[";
        s += float_text(tf.range->min);
        s += ", " + float_text(tf.range->max) + "]";
    } else {
        s += "none";
    }
    s += ", color=[";
    for (size_t i = 0; i < tf.color.size(); ++i) s += (i ? ", " : "") + point_text(tf.color[i]);
    s += "], opacity=[";
    for (size_t i = 0; i < tf.opacity.size(); ++i) s += (i ? ", " : "") + point_text(tf.opacity[i]);
    s += "]";
    const TfRendering& r = tf.rendering;
    if (r.shading) s += ", shading=" + shading_text(*r.shading);
    if (!r.gradient_opacity.empty()) {
        s += ", gradient_opacity=[";
        for (size_t i = 0; i < r.gradient_opacity.size(); ++i)
            s += (i ? ", " : "") + point_text(r.gradient_opacity[i]);
        s += "]";
    }
    if (r.blend) s += ", blend=" + to_string(*r.blend);
    return s + "}";
}

bool operator==(const TransferFunction& a, const TransferFunction& b) {
    // ValueRange has no operator==, so the optional range is compared by hand.
    const bool ranges_equal =
        a.range.has_value() == b.range.has_value() &&
        (!a.range || (a.range->min == b.range->min && a.range->max == b.range->max));
    return a.name == b.name && a.domain == b.domain && a.color == b.color &&
           a.opacity == b.opacity && ranges_equal && a.rendering == b.rendering;
}

void PrintTo(const TransferFunction& tf, std::ostream* os) {
    *os << to_string(tf);
}

TransferFunction lerp(const TransferFunction& a, const TransferFunction& b, float w) {
    using tf_detail::float_text;
    if (!(w >= 0.f && w <= 1.f))
        throw Error("lerp", "w", "expected a weight in [0,1], got " + float_text(w));
    tf_detail::validate(a, tf_where(a));
    tf_detail::validate(b, tf_where(b));
    if (a.domain != b.domain)
        throw Error("lerp", "domain",
                    "expected two TFs with the same domain, got '" + a.name + "' (" +
                        to_string(a.domain) + ") and '" + b.name + "' (" + to_string(b.domain) +
                        ")");
    // A range gives normalized x its meaning; blending a TF that has one with one that takes
    // the volume's would blend two different value axes.
    if (a.range.has_value() != b.range.has_value())
        throw Error("lerp", "range",
                    "expected both TFs or neither to carry a range, got '" + a.name + "' " +
                        (a.range ? "with" : "without") + " and '" + b.name + "' " +
                        (b.range ? "with" : "without"));

    TransferFunction out;
    out.name = w == 0.f   ? a.name
               : w == 1.f ? b.name
                          : "lerp(" + a.name + ", " + b.name + ", " + float_text(w) + ")";
    out.domain = a.domain;
    out.rendering = a.rendering;
    out.color = tf_detail::blend(a.color, b.color, double(w));
    out.opacity = tf_detail::blend(a.opacity, b.opacity, double(w));
    if (a.range) {
        auto mix = [w](float p, float q) {
            return p == q ? p : float((1.0 - double(w)) * double(p) + double(w) * double(q));
        };
        out.range = ValueRange{mix(a.range->min, b.range->min), mix(a.range->max, b.range->max)};
    }
    return out;
}

TransferLut discretise(const TransferFunction& tf, ValueRange vis, int size) {
    using tf_detail::float_text;
    const std::string where = tf_where(tf);
    if (size < 2)
        throw Error(where, "lut size", "expected at least 2 entries, got " + std::to_string(size));
    tf_detail::validate(tf, where);
    if (tf.range) vis = *tf.range;
    check_lut_range(vis, size, where, "visualization range");

    TransferLut lut;
    lut.vis = vis;
    lut.entries.resize(size_t(size));
    for (int e = 0; e < size; ++e) {
        // t = e/(size-1) is the entry's position across vis; (1-t)*min + t*max equals the
        // header's vis.min + e*(vis.max-vis.min)/(size-1) and hits both ends exactly.
        const double t = double(e) / double(size - 1);
        const double x = tf.domain == TfDomain::Normalized
                             ? t
                             : (1.0 - t) * double(vis.min) + t * double(vis.max);
        const auto c = tf_detail::evaluate(tf.color, x);
        const auto o = tf_detail::evaluate(tf.opacity, x);
        lut.entries[size_t(e)] = Rgba{c[0], c[1], c[2], o[0]};
    }
    return lut;
}

}  // namespace lacuna
