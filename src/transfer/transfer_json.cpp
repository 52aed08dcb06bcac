// The transfer function JSON format (docs/transfer-functions.md): reader, writer, file loader.
//
// The reader checks the document's shape here (keys, types, arity, finiteness, values in [0,1],
// with the offending JSON quoted back) and leaves the cross-point rules (sorting, steps,
// normalized x in [0,1]) to tf_detail::validate(), which in-memory TFs go through as well.
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "lacuna/error.h"
#include "lacuna/transfer_function.h"
#include "transfer/number_text.h"
#include "transfer/validate.h"

namespace lacuna {

namespace {

using nlohmann::json;

constexpr const char* kKnownKeys =
    "name, description, domain, range, color, opacity, shading, gradient_opacity, blend";
constexpr std::array<const char*, 4> kShadingKeys = {"ambient", "diffuse", "specular",
                                                     "specular_power"};
constexpr std::pair<BlendMode, const char*> kBlends[] = {{BlendMode::Composite, "composite"},
                                                         {BlendMode::Mip, "mip"},
                                                         {BlendMode::MinIp, "minip"},
                                                         {BlendMode::Average, "average"}};

// A quoted, escaped JSON string; invalid UTF-8 is replaced rather than thrown on.
std::string json_string(const std::string& s) {
    return json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

// One-line rendering of a JSON value for error messages, cut after ~80 characters.
void brief_into(const json& j, std::string& out) {
    if (out.size() > 80) return;
    if (j.is_array()) {
        out += "[";
        for (size_t i = 0; i < j.size(); ++i) {
            if (i) out += ", ";
            brief_into(j[i], out);
        }
        out += "]";
    } else if (j.is_object()) {
        out += "{";
        bool first = true;
        for (const auto& [key, value] : j.items()) {
            if (!first) out += ", ";
            first = false;
            out += json_string(key) + ": ";
            brief_into(value, out);
        }
        out += "}";
    } else {
        // Strings come back escaped, so no raw newline can slip into the one-line message.
        out += j.dump(-1, ' ', false, json::error_handler_t::replace);
    }
}
std::string brief(const json& j) {
    std::string s;
    brief_into(j, s);
    if (s.size() > 80) s = s.substr(0, 77) + "...";
    return s;
}

std::string type_name(const json& j) {
    return j.type_name();
}

// nlohmann's message minus its "[json.exception.parse_error.101] " prefix, on one line.
std::string parse_error_text(const char* what) {
    std::string s = what;
    if (!s.empty() && s[0] == '[') {
        auto end = s.find("] ");
        if (end != std::string::npos) s = s.substr(end + 2);
    }
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

// A control point's numbers in JSON order (x first), from either [x, ...] or {"x": .., ...}.
// Throws with `shape` (what was expected) and the element quoted back when anything is off.
template <size_t N>
std::array<double, N> read_point(const json& elem, const std::array<const char*, N>& keys,
                                 const std::string& where, const std::string& field,
                                 const std::string& values_rule) {
    std::string shape_array = "[";
    std::string shape_object = "{";
    for (size_t i = 0; i < N; ++i) {
        shape_array += std::string(i ? ", " : "") + keys[i];
        shape_object += std::string(i ? ", " : "") + "\"" + keys[i] + "\": " + keys[i];
    }
    const std::string shape =
        (elem.is_object() ? shape_object + "}" : shape_array + "]") + " with " + values_rule;
    auto fail = [&]() { throw Error(where, field, "expected " + shape + ", got " + brief(elem)); };

    std::array<const json*, N> items{};
    if (elem.is_array()) {
        if (elem.size() != N) fail();
        for (size_t i = 0; i < N; ++i) items[i] = &elem[i];
    } else if (elem.is_object()) {
        if (elem.size() != N) fail();
        for (size_t i = 0; i < N; ++i) {
            auto it = elem.find(keys[i]);
            if (it == elem.end()) fail();
            items[i] = &*it;
        }
    } else {
        fail();
    }

    std::array<double, N> v{};
    for (size_t i = 0; i < N; ++i) {
        if (!items[i]->is_number()) fail();  // is_number() is false for true/false
        v[i] = items[i]->template get<double>();
        if (!std::isfinite(v[i])) fail();  // cannot come from the reader; kept for safety
        if (i > 0 && !(v[i] >= 0.0 && v[i] <= 1.0)) fail();
    }
    return v;
}

template <class P, size_t N, class Make>
std::vector<P> read_points(const json& doc, const char* key, const std::array<const char*, N>& keys,
                           const std::string& where, const std::string& values_rule, Make make) {
    std::string shape = "[";
    for (size_t i = 0; i < N; ++i) shape += std::string(i ? ", " : "") + keys[i];
    shape += "]";
    auto it = doc.find(key);
    if (it == doc.end())
        throw Error(where, key, "missing; expected an array of " + shape + " control points");
    if (!it->is_array())
        throw Error(where, key,
                    "expected an array of " + shape + " control points, got " + type_name(*it) +
                        " " + brief(*it));
    if (it->empty())
        throw Error(where, key, "expected at least one " + shape + " control point, got []");
    std::vector<P> pts;
    pts.reserve(it->size());
    for (size_t i = 0; i < it->size(); ++i) {
        const std::string field = std::string(key) + "[" + std::to_string(i) + "]";
        pts.push_back(make(read_point<N>((*it)[i], keys, where, field, values_rule)));
    }
    return pts;
}

// "shading": {"ambient": .., "diffuse": .., "specular": .., "specular_power": ..}, every key
// present and a number (the ranges are tf_detail::validate()'s).
TfShading read_shading(const json& j, const std::string& where) {
    const std::string shape =
        "an object {\"ambient\", \"diffuse\", \"specular\", \"specular_power\"} of numbers";
    if (!j.is_object()) throw Error(where, "shading", "expected " + shape + ", got " + brief(j));
    for (const auto& item : j.items()) {
        const std::string& key =
            item.key();  // (a named reference: clang's C++20 captures no bindings)
        if (std::find_if(kShadingKeys.begin(), kShadingKeys.end(),
                         [&](const char* k) { return key == k; }) == kShadingKeys.end())
            throw Error(where, "shading." + key, "unknown key; expected " + shape);
    }
    float v[4];
    for (size_t i = 0; i < 4; ++i) {
        const std::string field = std::string("shading.") + kShadingKeys[i];
        auto it = j.find(kShadingKeys[i]);
        if (it == j.end()) throw Error(where, field, "missing; expected " + shape);
        if (!it->is_number()) throw Error(where, field, "expected a number, got " + brief(*it));
        v[i] = float(it->get<double>());
    }
    return {v[0], v[1], v[2], v[3]};
}

BlendMode read_blend(const json& j, const std::string& where) {
    std::string names;
    for (const auto& [mode, name] : kBlends) {
        if (j.is_string() && j.get<std::string>() == name) return mode;
        names += (names.empty() ? "\"" : ", \"") + std::string(name) + "\"";
    }
    throw Error(where, "blend", "expected one of " + names + ", got " + brief(j));
}

}  // namespace

TransferFunction parse_transfer_function(const std::string& json_text, const std::string& where) {
    json doc;
    try {
        // Comments (// and /* */) are accepted so hand-written files can be annotated.
        doc = json::parse(json_text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const json::parse_error& e) {
        std::string what = "not valid JSON: " + parse_error_text(e.what());
        // e.byte is the 1-based offset where the reader gave up; NaN/Infinity literals (as
        // written by Python's json module) are the likely culprit if one sits just before it.
        const size_t end = std::min(json_text.size(), size_t(e.byte) + 8);
        const size_t begin = size_t(e.byte) > 12 ? size_t(e.byte) - 12 : 0;
        const std::string near = begin < end ? json_text.substr(begin, end - begin) : "";
        for (const char* lit : {"NaN", "nan", "Infinity", "inf"}) {
            if (near.find(lit) != std::string::npos) {
                what += " (NaN and Infinity are not JSON numbers)";
                break;
            }
        }
        throw Error(where, "json", what);
    } catch (const json::exception& e) {
        // out_of_range.406: a number beyond double, e.g. 1e999.
        throw Error(where, "json", "not valid JSON: " + parse_error_text(e.what()));
    }
    if (!doc.is_object())
        throw Error(where, "json",
                    "expected an object {\"color\": [...], \"opacity\": [...]} at the top level, "
                    "got " +
                        type_name(doc) + " " + brief(doc));

    for (const auto& [key, value] : doc.items()) {
        if (key != "name" && key != "description" && key != "domain" && key != "range" &&
            key != "color" && key != "opacity" && key != "shading" && key != "gradient_opacity" &&
            key != "blend")
            throw Error(where, json_string(key),
                        std::string("unknown key; expected one of: ") + kKnownKeys);
    }

    TransferFunction tf;
    if (auto it = doc.find("name"); it != doc.end()) {
        if (!it->is_string()) throw Error(where, "name", "expected a string, got " + brief(*it));
        tf.name = it->get<std::string>();
    } else {
        tf.name = std::filesystem::path(where).stem().string();
    }
    if (auto it = doc.find("description"); it != doc.end() && !it->is_string())
        throw Error(where, "description", "expected a string, got " + brief(*it));

    if (auto it = doc.find("domain"); it != doc.end()) {
        const std::string d = it->is_string() ? it->get<std::string>() : std::string();
        if (d == "normalized")
            tf.domain = TfDomain::Normalized;
        else if (d == "value")
            tf.domain = TfDomain::Value;
        else
            throw Error(where, "domain", "expected \"normalized\" or \"value\", got " + brief(*it));
    }

    if (auto it = doc.find("range"); it != doc.end() && !it->is_null()) {
        const json& r = *it;
        bool ok = r.is_array() && r.size() == 2 && r[0].is_number() && r[1].is_number();
        if (ok) {
            // Checked after rounding to float, the type the range is stored and used in.
            const double lo = r[0].get<double>(), hi = r[1].get<double>();
            const float flo = float(lo), fhi = float(hi);
            ok = std::isfinite(lo) && std::isfinite(hi) && std::isfinite(flo) &&
                 std::isfinite(fhi) && flo < fhi;
            if (ok) tf.range = ValueRange{flo, fhi};
        }
        if (!ok)
            throw Error(where, "range",
                        "expected [min, max] with finite min < max (or null), got " + brief(r));
    }

    tf.color = read_points<ColorPoint, 4>(
        doc, "color", {"x", "r", "g", "b"}, where, "r, g, b in [0,1]",
        [](const std::array<double, 4>& v) {
            return ColorPoint{v[0], float(v[1]), float(v[2]), float(v[3])};
        });
    tf.opacity = read_points<OpacityPoint, 2>(doc, "opacity", {"x", "a"}, where, "a in [0,1]",
                                              [](const std::array<double, 2>& v) {
                                                  return OpacityPoint{v[0], float(v[1])};
                                              });
    // The rendering the TF asks of the frame (TfRendering), each part optional.
    if (auto it = doc.find("shading"); it != doc.end())
        tf.rendering.shading = read_shading(*it, where);
    if (doc.contains("gradient_opacity"))
        tf.rendering.gradient_opacity =
            read_points<OpacityPoint, 2>(doc, "gradient_opacity", {"x", "a"}, where, "a in [0,1]",
                                         [](const std::array<double, 2>& v) {
                                             return OpacityPoint{v[0], float(v[1])};
                                         });
    if (auto it = doc.find("blend"); it != doc.end()) tf.rendering.blend = read_blend(*it, where);

    tf_detail::validate(tf, where);
    return tf;
}

TransferFunction load_transfer_function(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(path, "file", "expected a JSON transfer function file, got a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "file", std::string("cannot open: ") + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw Error(path, "file", std::string("cannot read: ") + std::strerror(errno));
    return parse_transfer_function(text.str(), path);
}

std::string to_json(const TransferFunction& tf) {
    using tf_detail::float_text;
    using tf_detail::point_text;
    tf_detail::validate(tf, tf.name.empty() ? std::string("transfer function") : tf.name);
    // Written by hand rather than through nlohmann's dump() so each control point sits on one
    // line and floats print in their shortest form (number_text.h).
    std::string s = "{\n";
    s += "  \"name\": " + json_string(tf.name) + ",\n";
    s += "  \"domain\": \"" + to_string(tf.domain) + "\",\n";
    if (tf.range)
        s += "  \"range\": [" + float_text(tf.range->min) + ", " + float_text(tf.range->max) +
             "],\n";
    s += "  \"color\": [\n";
    for (size_t i = 0; i < tf.color.size(); ++i)
        s += "    " + point_text(tf.color[i]) + (i + 1 < tf.color.size() ? ",\n" : "\n");
    s += "  ],\n  \"opacity\": [\n";
    for (size_t i = 0; i < tf.opacity.size(); ++i)
        s += "    " + point_text(tf.opacity[i]) + (i + 1 < tf.opacity.size() ? ",\n" : "\n");
    s += "  ]";
    const TfRendering& r = tf.rendering;
    if (r.shading) s += ",\n  \"shading\": " + tf_detail::shading_text(*r.shading);
    if (!r.gradient_opacity.empty()) {
        s += ",\n  \"gradient_opacity\": [\n";
        for (size_t i = 0; i < r.gradient_opacity.size(); ++i)
            s += "    " + point_text(r.gradient_opacity[i]) +
                 (i + 1 < r.gradient_opacity.size() ? ",\n" : "\n");
        s += "  ]";
    }
    if (r.blend)
        for (const auto& [mode, name] : kBlends)
            if (mode == *r.blend) s += ",\n  \"blend\": \"" + std::string(name) + "\"";
    s += "\n}\n";
    return s;
}

}  // namespace lacuna
