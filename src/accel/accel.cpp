#include "lacuna/accel.h"

#include "accel/accel_impl.h"
#include "lacuna/error.h"

namespace lacuna {

namespace {
struct Entry {
    AccelKind kind;
    const char* name;
};
constexpr Entry kAccels[] = {{AccelKind::None, "none"},         {AccelKind::Distance, "distance"},
                             {AccelKind::Chebyshev, "chebyshev"}, {AccelKind::Boolean, "boolean"},
                             {AccelKind::MinMax, "minmax"},     {AccelKind::Bitfield, "bitfield"},
                             {AccelKind::KdTree, "kdtree"},
                             {AccelKind::MinMaxInterval, "minmax-interval"},
                             {AccelKind::Grid, "grid"}};
}  // namespace

std::string to_string(AccelKind k) {
    for (const auto& e : kAccels)
        if (e.kind == k) return e.name;
    return "?";
}

std::vector<std::string> accel_names() {
    std::vector<std::string> out;
    for (const auto& e : kAccels) out.push_back(e.name);
    return out;
}

std::vector<AccelKind> all_accel_kinds() {
    std::vector<AccelKind> out;
    for (const auto& e : kAccels) out.push_back(e.kind);
    return out;
}

std::string to_string(Interpolation i) {
    return i == Interpolation::Nearest ? "nearest" : "trilinear";
}

Interpolation parse_interpolation(const std::string& name) {
    if (name == "trilinear") return Interpolation::Trilinear;
    if (name == "nearest") return Interpolation::Nearest;
    throw Error("--interpolation", "sampling",
                "unknown '" + name + "'; expected one of: trilinear, nearest");
}

AccelKind default_accel() { return AccelKind::Grid; }

AccelKind parse_accel(const std::string& name) {
    if (name == "auto") return default_accel();
    for (const auto& e : kAccels)
        if (name == e.name) return e.kind;
    std::string valid = "auto";
    for (const auto& e : kAccels) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
    throw Error("--accel", "structure", "unknown '" + name + "'; expected one of: " + valid);
}

std::unique_ptr<Accel> make_accel(AccelKind k, const Volume& volume, const AccelOptions& opts) {
    switch (k) {
        case AccelKind::None: return std::make_unique<NoAccel>();
        case AccelKind::MinMax:
        case AccelKind::MinMaxInterval: return std::make_unique<MinMaxOctree>(k, volume, opts);
        case AccelKind::Bitfield: return std::make_unique<BitfieldOctree>(volume, opts);
        case AccelKind::Boolean: return std::make_unique<BooleanOctree>(volume, opts);
        case AccelKind::Distance:
        case AccelKind::Chebyshev: return std::make_unique<DistanceMap>(k, volume, opts);
        case AccelKind::KdTree: return std::make_unique<KdTree>(volume, opts);
        case AccelKind::Grid: return std::make_unique<BrickGrid>(volume, opts);
    }
    throw Error("--accel", "structure", "unhandled kind");
}

}  // namespace lacuna
