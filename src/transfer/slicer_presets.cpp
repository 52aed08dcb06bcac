#include "transfer/slicer_presets.h"

#include <expat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lacuna/error.h"
#include "transfer/number_text.h"
#include "transfer/validate.h"

namespace lacuna {

namespace {

using nlohmann::json;

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return lower(s).ends_with(suffix);
}

std::string read_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(path, "file", "expected a Slicer preset file, got a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "file", std::string("cannot open: ") + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw Error(path, "file", std::string("cannot read: ") + std::strerror(errno));
    return text.str();
}

std::string shorten(const std::string& s) {
    return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// One whitespace-separated token as a finite double, or nullopt.
std::optional<double> number(const std::string& tok) {
    if (tok.empty()) return std::nullopt;
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (end != tok.c_str() + tok.size() || errno == ERANGE || !std::isfinite(v))
        return std::nullopt;
    return v;
}

std::vector<std::string> tokens(const std::string& s) {
    std::vector<std::string> out;
    std::istringstream in(s);
    for (std::string t; in >> t;) out.push_back(t);
    return out;
}

// A list of numbers; throws naming the token.
std::vector<double> numbers(const std::string& text, const std::string& where,
                            const std::string& field) {
    std::vector<double> out;
    for (const std::string& t : tokens(text)) {
        const auto v = number(t);
        if (!v) throw Error(where, field, "expected finite numbers, got '" + shorten(t) + "'");
        out.push_back(*v);
    }
    return out;
}

double in_unit(double v, const std::string& where, const std::string& field, const char* what) {
    if (!(v >= 0.0 && v <= 1.0))
        throw Error(
            where, field,
            std::string("expected ") + what + " in [0,1], got " + tf_detail::double_text(v));
    return v;
}

// VTK's point insertion: sorted by x, a later point at the same x replaces the earlier one.
template <class P>
std::vector<P> vtk_points(std::vector<P> pts) {
    std::stable_sort(pts.begin(), pts.end(), [](const P& a, const P& b) { return a.x < b.x; });
    std::vector<P> out;
    for (const P& p : pts) {
        if (!out.empty() && out.back().x == p.x)
            out.back() = p;
        else
            out.push_back(p);
    }
    return out;
}

// "N x0 a0 x1 a1 ...": N numbers follow, `per` per point.
std::vector<double> counted(const std::string& text, int per, const std::string& where,
                            const std::string& field) {
    const std::vector<double> v = numbers(text, where, field);
    const char* layout = per == 2 ? "pairs x a" : "quadruples x r g b";
    if (v.empty())
        throw Error(where, field,
                    std::string("expected a count N and N numbers (") + layout + "), got nothing");
    const double n = v[0];
    // Compared as doubles before any integer conversion: a count of 1e39 must not reach
    // int64_t or size_t (UB).
    if (!(n >= per) || n != std::floor(n) || (n <= double(v.size()) && int64_t(n) % per != 0))
        throw Error(where, field,
                    "expected a count N that is a positive multiple of " + std::to_string(per) +
                        " (" + layout + "), got " + tf_detail::double_text(n));
    if (n != double(v.size() - 1))
        throw Error(where, field,
                    "expected " + tf_detail::double_text(n) + " numbers after the count, got " +
                        std::to_string(v.size() - 1));
    return std::vector<double>(v.begin() + 1, v.end());
}

std::vector<OpacityPoint> opacity_points(const std::string& text, const std::string& where,
                                         const std::string& field) {
    const std::vector<double> v = counted(text, 2, where, field);
    std::vector<OpacityPoint> out;
    for (size_t i = 0; i < v.size(); i += 2) {
        const std::string f = field + "[" + std::to_string(i / 2) + "]";
        out.push_back({v[i], float(in_unit(v[i + 1], where, f, "opacity"))});
    }
    return vtk_points(std::move(out));
}

std::vector<ColorPoint> color_points(const std::string& text, const std::string& where,
                                     const std::string& field) {
    const std::vector<double> v = counted(text, 4, where, field);
    std::vector<ColorPoint> out;
    for (size_t i = 0; i < v.size(); i += 4) {
        const std::string f = field + "[" + std::to_string(i / 4) + "]";
        out.push_back({v[i], float(in_unit(v[i + 1], where, f, "r")),
                       float(in_unit(v[i + 2], where, f, "g")),
                       float(in_unit(v[i + 3], where, f, "b"))});
    }
    return vtk_points(std::move(out));
}

double scalar(const std::string& text, const std::string& where, const std::string& field) {
    const auto t = tokens(text);
    const auto v = t.size() == 1 ? number(t[0]) : std::nullopt;
    if (!v) throw Error(where, field, "expected one number, got '" + shorten(text) + "'");
    return *v;
}

bool flag(const std::string& text, const std::string& where, const std::string& field) {
    const auto t = tokens(text);
    if (t.size() == 1 && (t[0] == "0" || t[0] == "1")) return t[0] == "1";
    if (t.size() == 1 && (t[0] == "true" || t[0] == "false")) return t[0] == "true";
    throw Error(where, field, "expected 0 or 1, got '" + shorten(text) + "'");
}

SlicerInterpolation interpolation_code(const std::string& text, const std::string& where,
                                       const std::string& field) {
    const auto t = tokens(text);
    if (t.size() == 1 && t[0] == "0") return SlicerInterpolation::Nearest;
    if (t.size() == 1 && t[0] == "1") return SlicerInterpolation::Linear;
    throw Error(where, field, "expected 0 (nearest) or 1 (linear), got '" + shorten(text) + "'");
}

void check_shading(const SlicerShading& s, const std::string& where, const std::string& entry) {
    in_unit(s.ambient, where, entry + "ambient", "ambient");
    in_unit(s.diffuse, where, entry + "diffuse", "diffuse");
    in_unit(s.specular, where, entry + "specular", "specular");
    if (!(s.specular_power >= 0.f))
        throw Error(where, entry + "specularPower",
                    "expected a number >= 0, got " + tf_detail::float_text(s.specular_power));
}

ValueRange range_of(double lo, double hi, const std::string& where, const std::string& field,
                    const std::string& text) {
    const ValueRange r{float(lo), float(hi)};
    if (!(std::isfinite(r.min) && std::isfinite(r.max) && r.min < r.max))
        throw Error(where, field,
                    "expected two finite numbers lo < hi, got '" + shorten(text) + "'");
    return r;
}

// ---- presets.xml ------------------------------------------------------------------------------

struct XmlEntry {
    std::map<std::string, std::string> attrs;
    int line = 0;
};

struct XmlState {
    std::vector<XmlEntry> entries;
    XML_Parser parser = nullptr;
};

void XMLCALL on_start(void* data, const XML_Char* name, const XML_Char** attrs) {
    auto* st = static_cast<XmlState*>(data);
    if (std::strcmp(name, "VolumeProperty") != 0) return;
    XmlEntry e;
    e.line = int(XML_GetCurrentLineNumber(st->parser));
    for (int i = 0; attrs[i]; i += 2) e.attrs[attrs[i]] = attrs[i + 1];
    st->entries.push_back(std::move(e));
}

SlicerVolumeProperty xml_entry(const XmlEntry& e, const std::string& where) {
    SlicerVolumeProperty p;
    p.source = where;
    const auto name = e.attrs.find("name");
    std::string entry = "VolumeProperty at line " + std::to_string(e.line);
    if (name == e.attrs.end() || name->second.empty())
        throw Error(where, entry, "expected a non-empty name attribute");
    p.name = name->second;
    entry = "VolumeProperty \"" + p.name + "\" (line " + std::to_string(e.line) + ")";
    auto get = [&](const char* key) -> const std::string* {
        const auto it = e.attrs.find(key);
        return it == e.attrs.end() ? nullptr : &it->second;
    };
    auto need = [&](const char* key, const char* what) -> const std::string& {
        const std::string* v = get(key);
        if (!v) throw Error(where, entry + ": " + key, std::string("missing; expected ") + what);
        return *v;
    };
    const std::string f = entry + ": ";
    p.scalar_opacity =
        opacity_points(need("scalarOpacity", "\"N x a x a ...\""), where, f + "scalarOpacity");
    p.color = color_points(need("colorTransfer", "\"N x r g b ...\""), where, f + "colorTransfer");
    if (const std::string* v = get("gradientOpacity"))
        p.gradient_opacity = opacity_points(*v, where, f + "gradientOpacity");
    if (const std::string* v = get("interpolation"))
        p.interpolation = interpolation_code(*v, where, f + "interpolation");
    if (const std::string* v = get("shade")) p.shading.shade = flag(*v, where, f + "shade");
    if (const std::string* v = get("ambient"))
        p.shading.ambient = float(scalar(*v, where, f + "ambient"));
    if (const std::string* v = get("diffuse"))
        p.shading.diffuse = float(scalar(*v, where, f + "diffuse"));
    if (const std::string* v = get("specular"))
        p.shading.specular = float(scalar(*v, where, f + "specular"));
    if (const std::string* v = get("specularPower"))
        p.shading.specular_power = float(scalar(*v, where, f + "specularPower"));
    check_shading(p.shading, where, f);
    if (const std::string* v = get("effectiveRange")) {
        const std::vector<double> r = numbers(*v, where, f + "effectiveRange");
        if (r.size() != 2)
            throw Error(where, f + "effectiveRange",
                        "expected two numbers \"lo hi\", got '" + shorten(*v) + "'");
        p.effective_range = range_of(r[0], r[1], where, f + "effectiveRange", *v);
    }
    return p;
}

// ---- .vp.json ---------------------------------------------------------------------------------

const json& member(const json& obj, const char* key, const std::string& where,
                   const std::string& path, const char* expected) {
    if (!obj.is_object() || !obj.contains(key))
        throw Error(where, path + key, std::string("missing; expected ") + expected);
    return obj.at(key);
}

double json_number(const json& v, const std::string& where, const std::string& field) {
    if (!v.is_number()) throw Error(where, field, "expected a number, got " + shorten(v.dump()));
    return v.get<double>();
}

void linear_segment(const json& pt, const std::string& where, const std::string& field) {
    const double mid =
        json_number(member(pt, "midpoint", where, field + ".", "0.5"), where, field + ".midpoint");
    const double sharp =
        json_number(member(pt, "sharpness", where, field + ".", "0"), where, field + ".sharpness");
    if (mid != 0.5 || sharp != 0.0)
        throw Error(where, field,
                    "expected midpoint 0.5 and sharpness 0 (lacuna's TFs are piecewise linear), "
                    "got midpoint " +
                        tf_detail::double_text(mid) + ", sharpness " +
                        tf_detail::double_text(sharp));
}

const json& points_of(const json& fn, const std::string& where, const std::string& field) {
    const json& pts = member(fn, "points", where, field + ".", "an array of points");
    if (!pts.is_array() || pts.empty())
        throw Error(where, field + ".points", "expected a non-empty array of points");
    return pts;
}

std::vector<OpacityPoint> json_opacity(const json& fn, const std::string& where,
                                       const std::string& field) {
    std::vector<OpacityPoint> out;
    const json& pts = points_of(fn, where, field);
    for (size_t i = 0; i < pts.size(); ++i) {
        const std::string f = field + ".points[" + std::to_string(i) + "]";
        const double x =
            json_number(member(pts[i], "x", where, f + ".", "a number"), where, f + ".x");
        const double y =
            json_number(member(pts[i], "y", where, f + ".", "a number"), where, f + ".y");
        linear_segment(pts[i], where, f);
        out.push_back({x, float(in_unit(y, where, f + ".y", "opacity"))});
    }
    return vtk_points(std::move(out));
}

std::vector<ColorPoint> json_color(const json& fn, const std::string& where,
                                   const std::string& field, bool gray) {
    std::vector<ColorPoint> out;
    const json& pts = points_of(fn, where, field);
    for (size_t i = 0; i < pts.size(); ++i) {
        const std::string f = field + ".points[" + std::to_string(i) + "]";
        const double x =
            json_number(member(pts[i], "x", where, f + ".", "a number"), where, f + ".x");
        linear_segment(pts[i], where, f);
        if (gray) {
            const double y =
                json_number(member(pts[i], "y", where, f + ".", "a number"), where, f + ".y");
            const float g = float(in_unit(y, where, f + ".y", "grey"));
            out.push_back({x, g, g, g});
            continue;
        }
        const json& c = member(pts[i], "color", where, f + ".", "[r, g, b]");
        if (!c.is_array() || c.size() != 3)
            throw Error(where, f + ".color", "expected [r, g, b], got " + shorten(c.dump()));
        float rgb[3];
        for (int k = 0; k < 3; ++k)
            rgb[k] = float(in_unit(json_number(c[size_t(k)], where, f + ".color"), where,
                                   f + ".color", "r, g, b"));
        out.push_back({x, rgb[0], rgb[1], rgb[2]});
    }
    return vtk_points(std::move(out));
}

SlicerVolumeProperty json_entry(const json& vp, size_t index, const std::string& where) {
    const std::string path = "volumeProperties[" + std::to_string(index) + "]";
    if (!vp.is_object()) throw Error(where, path, "expected an object");
    SlicerVolumeProperty p;
    p.source = where;
    p.name = std::to_string(index);
    if (vp.contains("name")) {
        if (!vp["name"].is_string() || vp["name"].get<std::string>().empty())
            throw Error(where, path + ".name", "expected a non-empty string");
        p.name = vp["name"].get<std::string>();
    }
    if (vp.contains("effectiveRange")) {
        const json& r = vp["effectiveRange"];
        if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number())
            throw Error(where, path + ".effectiveRange",
                        "expected [lo, hi] with lo < hi, got " + shorten(r.dump()));
        p.effective_range = range_of(r[0].get<double>(), r[1].get<double>(), where,
                                     path + ".effectiveRange", r.dump());
    }
    if (vp.contains("interpolationType")) {
        const json& t = vp["interpolationType"];
        const std::string s = t.is_string() ? t.get<std::string>() : "";
        if (s == "nearest")
            p.interpolation = SlicerInterpolation::Nearest;
        else if (s == "linear")
            p.interpolation = SlicerInterpolation::Linear;
        else if (s == "cubic")
            p.interpolation = SlicerInterpolation::Cubic;
        else
            throw Error(where, path + ".interpolationType",
                        "expected \"nearest\", \"linear\" or \"cubic\", got " + shorten(t.dump()));
    }
    if (vp.contains("independentComponents") && vp["independentComponents"] == true)
        throw Error(where, path + ".independentComponents",
                    "expected false (lacuna renders single-component volumes)");
    const json& comps = member(vp, "components", where, path + ".", "an array of one component");
    if (!comps.is_array() || comps.size() != 1)
        throw Error(where, path + ".components",
                    "expected exactly one component (lacuna renders single-component volumes), "
                    "got " +
                        (comps.is_array() ? std::to_string(comps.size()) : shorten(comps.dump())));
    const json& c = comps[0];
    const std::string cp = path + ".components[0]";
    if (!c.is_object()) throw Error(where, cp, "expected an object");
    if (c.contains("shade")) {
        if (!c["shade"].is_boolean()) throw Error(where, cp + ".shade", "expected true or false");
        p.shading.shade = c["shade"].get<bool>();
    }
    if (c.contains("lighting")) {
        const json& l = c["lighting"];
        const std::string lp = cp + ".lighting.";
        p.shading.ambient = float(json_number(member(l, "ambient", where, lp, "a number in [0,1]"),
                                              where, lp + "ambient"));
        p.shading.diffuse = float(json_number(member(l, "diffuse", where, lp, "a number in [0,1]"),
                                              where, lp + "diffuse"));
        p.shading.specular = float(json_number(
            member(l, "specular", where, lp, "a number in [0,1]"), where, lp + "specular"));
        p.shading.specular_power = float(json_number(
            member(l, "specularPower", where, lp, "a number >= 0"), where, lp + "specularPower"));
        check_shading(p.shading, where, lp);
    }
    if (c.contains("disableGradientOpacity")) {
        if (!c["disableGradientOpacity"].is_boolean())
            throw Error(where, cp + ".disableGradientOpacity", "expected true or false");
        p.gradient_opacity_enabled = !c["disableGradientOpacity"].get<bool>();
    }
    if (c.contains("scalarOpacityUnitDistance")) {
        const double d =
            json_number(c["scalarOpacityUnitDistance"], where, cp + ".scalarOpacityUnitDistance");
        if (!(d > 0))
            throw Error(where, cp + ".scalarOpacityUnitDistance",
                        "expected a number > 0, got " + tf_detail::double_text(d));
        p.scalar_opacity_unit_distance = d;
    }
    p.scalar_opacity =
        json_opacity(member(c, "scalarOpacity", where, cp + ".", "{\"points\": [...]}"), where,
                     cp + ".scalarOpacity");
    if (c.contains("gradientOpacity"))
        p.gradient_opacity = json_opacity(c["gradientOpacity"], where, cp + ".gradientOpacity");
    if (c.contains("rgbTransferFunction"))
        p.color = json_color(c["rgbTransferFunction"], where, cp + ".rgbTransferFunction", false);
    else if (c.contains("grayTransferFunction"))
        p.color = json_color(c["grayTransferFunction"], where, cp + ".grayTransferFunction", true);
    else
        throw Error(
            where, cp + ".rgbTransferFunction",
            "missing; expected a colour function (rgbTransferFunction or grayTransferFunction)");
    return p;
}

}  // namespace

std::string to_string(SlicerInterpolation i) {
    switch (i) {
        case SlicerInterpolation::Nearest:
            return "nearest";
        case SlicerInterpolation::Linear:
            return "linear";
        case SlicerInterpolation::Cubic:
            return "cubic";
    }
    return "?";
}

std::string to_string(const SlicerVolumeProperty& p) {
    std::string s = "SlicerVolumeProperty \"" + p.name + "\" from " + p.source + ": " +
                    std::to_string(p.scalar_opacity.size()) + " opacity, " +
                    std::to_string(p.color.size()) + " colour, " +
                    std::to_string(p.gradient_opacity.size()) + " gradient-opacity points, " +
                    "shade " + (p.shading.shade ? "on" : "off") + ", " + to_string(p.interpolation);
    if (p.effective_range)
        s += ", effective range [" + tf_detail::float_text(p.effective_range->min) + ", " +
             tf_detail::float_text(p.effective_range->max) + "]";
    return s;
}

std::vector<SlicerVolumeProperty> parse_slicer_presets_xml(const std::string& xml,
                                                           const std::string& where) {
    XmlState st;
    st.parser = XML_ParserCreate(nullptr);
    if (!st.parser) throw Error(where, "xml", "cannot create the XML parser");
    XML_SetUserData(st.parser, &st);
    XML_SetStartElementHandler(st.parser, on_start);
    const XML_Status ok = XML_Parse(st.parser, xml.data(), int(xml.size()), XML_TRUE);
    if (ok != XML_STATUS_OK) {
        const std::string msg = "not well-formed XML at line " +
                                std::to_string(XML_GetCurrentLineNumber(st.parser)) + ", column " +
                                std::to_string(XML_GetCurrentColumnNumber(st.parser)) + ": " +
                                XML_ErrorString(XML_GetErrorCode(st.parser));
        XML_ParserFree(st.parser);
        throw Error(where, "xml", msg);
    }
    XML_ParserFree(st.parser);
    if (st.entries.empty())
        throw Error(where, "VolumeProperty", "expected at least one <VolumeProperty> element");
    std::vector<SlicerVolumeProperty> out;
    for (const XmlEntry& e : st.entries) {
        out.push_back(xml_entry(e, where));
        for (size_t i = 0; i + 1 < out.size(); ++i)
            if (out[i].name == out.back().name)
                throw Error(where,
                            "VolumeProperty \"" + out.back().name + "\" (line " +
                                std::to_string(e.line) + ")",
                            "expected unique names, the name is used twice");
    }
    return out;
}

SlicerVolumeProperty parse_slicer_vp(const std::string& text, const std::string& where) {
    // Nine lines (trailing blank lines and \r ignored).
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
        if (!l.empty() && l.back() == '\r') l.pop_back();
        lines.push_back(l);
    }
    while (!lines.empty() && tokens(lines.back()).empty()) lines.pop_back();
    static const char* kLines[9] = {
        "interpolation",  "shade",          "diffuse",          "ambient",        "specular",
        "specular power", "scalar opacity", "gradient opacity", "colour transfer"};
    if (lines.size() != 9)
        throw Error(where, "lines",
                    "expected 9 lines (interpolation, shade, diffuse, ambient, specular, specular "
                    "power, scalar opacity, gradient opacity, colour), got " +
                        std::to_string(lines.size()));
    auto field = [&](int i) { return "line " + std::to_string(i + 1) + " (" + kLines[i] + ")"; };
    SlicerVolumeProperty p;
    p.source = where;
    std::string stem = std::filesystem::path(where).filename().string();
    if (ends_with(stem, ".vp")) stem.resize(stem.size() - 3);
    p.name = stem;
    p.interpolation = interpolation_code(lines[0], where, field(0));
    p.shading.shade = flag(lines[1], where, field(1));
    p.shading.diffuse = float(scalar(lines[2], where, field(2)));
    p.shading.ambient = float(scalar(lines[3], where, field(3)));
    p.shading.specular = float(scalar(lines[4], where, field(4)));
    p.shading.specular_power = float(scalar(lines[5], where, field(5)));
    check_shading(p.shading, where, "");
    p.scalar_opacity = opacity_points(lines[6], where, field(6));
    p.gradient_opacity = opacity_points(lines[7], where, field(7));
    p.color = color_points(lines[8], where, field(8));
    return p;
}

std::vector<SlicerVolumeProperty> parse_slicer_vp_json(const std::string& text,
                                                       const std::string& where) {
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::exception& e) {
        // parse_error, and out_of_range.406 for a number beyond double (1e999).
        std::string what = e.what();
        const size_t b = what.find("] ");
        if (b != std::string::npos) what = what.substr(b + 2);
        std::replace(what.begin(), what.end(), '\n', ' ');
        throw Error(where, "json", "not valid JSON: " + what);
    }
    if (!doc.is_object()) throw Error(where, "json", "expected an object with volumeProperties");
    const json& props = member(doc, "volumeProperties", where, "", "an array of volume properties");
    if (!props.is_array() || props.empty())
        throw Error(where, "volumeProperties", "expected a non-empty array");
    std::vector<SlicerVolumeProperty> out;
    for (size_t i = 0; i < props.size(); ++i) out.push_back(json_entry(props[i], i, where));
    return out;
}

std::vector<SlicerVolumeProperty> load_slicer_file(const std::string& path) {
    if (ends_with(path, ".vp.json")) return parse_slicer_vp_json(read_file(path), path);
    if (ends_with(path, ".vp")) return {parse_slicer_vp(read_file(path), path)};
    if (ends_with(path, ".xml")) return parse_slicer_presets_xml(read_file(path), path);
    throw Error(path, "file", "expected a Slicer preset file ending in .xml, .vp or .vp.json");
}

bool is_slicer_spec(const std::string& spec) {
    if (spec.rfind("slicer:", 0) == 0) return true;
    const std::string file = spec.substr(0, spec.find('#'));
    return ends_with(file, ".vp") || ends_with(file, ".vp.json");
}

SlicerVolumeProperty resolve_slicer_preset(const std::string& spec) {
    std::string s = spec.rfind("slicer:", 0) == 0 ? spec.substr(7) : spec;
    const size_t hash = s.find('#');
    const std::string file = s.substr(0, hash);
    const std::optional<std::string> name =
        hash == std::string::npos ? std::nullopt : std::optional<std::string>(s.substr(hash + 1));
    if (file.empty())
        throw Error("tf", "slicer", "expected slicer:FILE.xml#NAME, FILE.vp or FILE.vp.json");
    const std::vector<SlicerVolumeProperty> all = load_slicer_file(file);
    std::string names;
    for (const auto& p : all) names += (names.empty() ? "" : ", ") + p.name;
    if (!name) {
        if (all.size() == 1) return all[0];
        throw Error(file, "preset",
                    "expected a preset name after '#' (e.g. " + file + "#" + all[0].name +
                        "); the file holds: " + names);
    }
    for (const auto& p : all)
        if (p.name == *name) return p;
    throw Error(file, "preset", "unknown '" + *name + "'; expected one of: " + names);
}

TransferFunction to_transfer_function(const SlicerVolumeProperty& p) {
    TransferFunction tf;
    tf.name = p.name;
    tf.domain = TfDomain::Value;
    tf.color = p.color;
    tf.opacity = p.scalar_opacity;
    tf.range = p.effective_range;
    // The rest of the volume property: the frame's defaults (apply_tf_rendering).
    if (p.shading.shade)
        tf.rendering.shading = TfShading{p.shading.ambient, p.shading.diffuse, p.shading.specular,
                                         p.shading.specular_power};
    if (p.gradient_opacity_enabled) tf.rendering.gradient_opacity = p.gradient_opacity;
    tf_detail::validate(tf, p.source + "#" + p.name);
    return tf;
}

}  // namespace lacuna
