// Label tables for segment visibility (include/lacuna/segments.h, docs/segments.md): defaults,
// our JSON format, MRIcron .lut colour tables with their .txt names, visibility lists.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lacuna/error.h"
#include "lacuna/segments.h"

namespace lacuna {

namespace {

using nlohmann::json;

}  // namespace

int label_count(const Volume& v) {
    int mx = 0;
    visit_voxels(v, [&](const auto* data) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        const size_t n = v.voxel_count();
        T m = data[0];
        for (size_t i = 1; i < n; ++i) m = data[i] > m ? data[i] : m;
        mx = int(m);
    });
    return mx + 1;
}

namespace {

void hsv_to_rgb(float h, float s, float v, LabelStyle& c) {
    const float i = std::floor(h * 6.f), f = h * 6.f - i;
    const float p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    switch (int(i) % 6) {
        case 0:
            c.r = v, c.g = t, c.b = p;
            break;
        case 1:
            c.r = q, c.g = v, c.b = p;
            break;
        case 2:
            c.r = p, c.g = v, c.b = t;
            break;
        case 3:
            c.r = p, c.g = q, c.b = v;
            break;
        case 4:
            c.r = t, c.g = p, c.b = v;
            break;
        default:
            c.r = v, c.g = p, c.b = q;
            break;
    }
}

std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "file", "cannot be opened");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

float unit_number(const json& j, const std::string& path, const std::string& field) {
    if (!j.is_number()) throw Error(path, field, "expected a number in [0,1], got " + j.dump());
    const double v = j.get<double>();
    if (!(v >= 0.0 && v <= 1.0))
        throw Error(path, field, "expected a number in [0,1], got " + j.dump());
    return float(v);
}

void apply_json(LabelTable& t, const std::string& text, const std::string& path) {
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::exception& e) {
        throw Error(path, "JSON", std::string("malformed (") + e.what() + ")");
    }
    if (!doc.is_object() || !doc.contains("labels") || !doc["labels"].is_array())
        throw Error(path, "labels", "expected an object with a \"labels\" array");
    for (const auto& [key, value] : doc.items())
        if (key != "labels" && key != "name" && key != "description")
            throw Error(path, key, "unknown key; expected labels, name, description");
    const json& arr = doc["labels"];
    for (size_t i = 0; i < arr.size(); ++i) {
        const std::string f = "labels[" + std::to_string(i) + "]";
        const json& e = arr[i];
        if (!e.is_object()) throw Error(path, f, "expected an object");
        if (!e.contains("label") || !e["label"].is_number_integer())
            throw Error(path, f + ".label", "expected an integer label value");
        const long long l = e["label"].get<long long>();
        if (l < 0 || l > kMaxLabel)
            throw Error(path, f + ".label",
                        "expected 0.." + std::to_string(kMaxLabel) + ", got " + std::to_string(l));
        if (l >= t.size()) t.styles.resize(size_t(l) + 1);
        LabelStyle& s = t.styles[size_t(l)];
        for (const auto& [key, v] : e.items()) {
            if (key == "label") continue;
            if (key == "name") {
                if (!v.is_string()) throw Error(path, f + ".name", "expected a string");
                s.name = v.get<std::string>();
            } else if (key == "color") {
                if (!v.is_array() || v.size() != 3)
                    throw Error(path, f + ".color", "expected [r, g, b] in [0,1]");
                s.r = unit_number(v[0], path, f + ".color[0]");
                s.g = unit_number(v[1], path, f + ".color[1]");
                s.b = unit_number(v[2], path, f + ".color[2]");
            } else if (key == "opacity") {
                s.opacity = unit_number(v, path, f + ".opacity");
            } else if (key == "visible") {
                if (!v.is_boolean()) throw Error(path, f + ".visible", "expected true or false");
                s.visible = v.get<bool>();
            } else {
                throw Error(path, f + "." + key,
                            "unknown key; expected label, name, color, opacity, visible");
            }
        }
    }
}

// MRIcron's .lut: 256 reds, 256 greens, 256 blues (bytes). Names from NAME.txt ("1 Precentral_L
// 2001" per line) when it exists.
void apply_lut(LabelTable& t, const std::string& bytes, const std::string& path) {
    if (bytes.size() != 768)
        throw Error(
            path, "size",
            "expected an MRIcron colour table of 768 bytes, got " + std::to_string(bytes.size()));
    for (int l = 0; l < std::min(256, t.size()); ++l) {
        LabelStyle& s = t.styles[size_t(l)];
        s.r = float(uint8_t(bytes[size_t(l)])) / 255.f;
        s.g = float(uint8_t(bytes[size_t(256 + l)])) / 255.f;
        s.b = float(uint8_t(bytes[size_t(512 + l)])) / 255.f;
    }
    std::filesystem::path names(path);
    names.replace_extension(".txt");
    std::ifstream in(names);
    for (std::string line; std::getline(in, line);) {
        std::istringstream ls(line);
        int l;
        std::string name;
        if (ls >> l >> name && l >= 0 && l < t.size()) t.styles[size_t(l)].name = name;
    }
}

}  // namespace

void check_label_volume(const Volume& labels, const Volume* intensity, const std::string& where) {
    if (labels.type() == VoxelType::Float32)
        throw Error(where, "voxel type",
                    "expected an integer label map (uint8, int16, uint16), got float32");
    if (labels.type() == VoxelType::Int16) {
        const int16_t* d = labels.data_as<int16_t>();
        for (size_t i = 0, n = labels.voxel_count(); i < n; ++i)
            if (d[i] < 0)
                throw Error(where, "labels",
                            "expected non-negative label values, found " + std::to_string(d[i]));
    }
    if (intensity) {
        const Vec3i a = labels.dims(), b = intensity->dims();
        if (a.x != b.x || a.y != b.y || a.z != b.z)
            throw Error(where, "dims",
                        "expected the intensity volume's " + std::to_string(b.x) + "x" +
                            std::to_string(b.y) + "x" + std::to_string(b.z) + ", got " +
                            std::to_string(a.x) + "x" + std::to_string(a.y) + "x" +
                            std::to_string(a.z));
    }
}

LabelTable default_label_table(const Volume& labels) {
    LabelTable t;
    t.styles.resize(size_t(label_count(labels)));
    for (int l = 0; l < t.size(); ++l) {
        LabelStyle& s = t.styles[size_t(l)];
        // Golden-ratio hue steps keep neighbouring label numbers apart in colour.
        hsv_to_rgb(std::fmod(0.61803398875f * float(l), 1.f), 0.65f, 0.95f, s);
        s.visible = l != 0;
    }
    return t;
}

LabelTable load_label_table(const std::string& path, const Volume& labels) {
    LabelTable t = default_label_table(labels);
    const std::string text = read_file(path);
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext == ".lut")
        apply_lut(t, text, path);
    else if (ext == ".json")
        apply_json(t, text, path);
    else
        throw Error(path, "label style", "expected a .json label table or an MRIcron .lut");
    return t;
}

void set_label_visibility(LabelTable& t, const std::string& spec, bool visible,
                          const std::string& where) {
    if (spec == "all" || spec == "none") {
        const bool v = spec == "all" ? visible : !visible;
        for (int l = 1; l < t.size(); ++l) t.styles[size_t(l)].visible = v;
        return;
    }
    std::stringstream in(spec);
    bool any = false;
    for (std::string item; std::getline(in, item, ',');) {
        const size_t dash = item.find('-');
        const std::string a = item.substr(0, dash);
        const std::string b = dash == std::string::npos ? a : item.substr(dash + 1);
        auto num = [&](const std::string& s) {
            if (s.empty() || s.size() > 5 || s.find_first_not_of("0123456789") != std::string::npos)
                throw Error(where, "labels",
                            "expected 'all', 'none' or a list like 1,2,37-40, got '" + spec + "'");
            return std::stoi(s);
        };
        const int lo = num(a), hi = num(b);
        if (lo > hi || hi > kMaxLabel)
            throw Error(where, "labels",
                        "expected ranges lo-hi with lo <= hi <= " + std::to_string(kMaxLabel) +
                            ", got '" + item + "'");
        if (hi >= t.size()) t.styles.resize(size_t(hi) + 1);
        for (int l = lo; l <= hi; ++l) t.styles[size_t(l)].visible = visible;
        any = true;
    }
    if (!any) throw Error(where, "labels", "expected at least one label");
}

std::string to_string(SegmentMode m) {
    return m == SegmentMode::Labels ? "labels" : "mask";
}

SegmentMode parse_segment_mode(const std::string& s, const std::string& where) {
    if (s == "labels") return SegmentMode::Labels;
    if (s == "mask") return SegmentMode::Masked;
    throw Error(where, "mode", "expected 'mask' or 'labels', got '" + s + "'");
}

}  // namespace lacuna
