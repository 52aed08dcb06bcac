#include "lacuna/accel.h"

#include "lacuna/error.h"
#include "session/structure_registry.h"

namespace lacuna {

// The names and kinds are the registry's (src/session/structure_registry.h): the entries with a
// ray face, in its order.
namespace {
template <class F>
void for_each_ray(F&& f) {
    for (const registry::Entry& e : registry::kStructures)
        if (e.ray) f(*e.ray, e.name);
}
}  // namespace

std::string to_string(AccelKind k) {
    std::string out = "?";
    for_each_ray([&](AccelKind kind, const char* name) {
        if (kind == k) out = name;
    });
    return out;
}

std::vector<std::string> accel_names() {
    std::vector<std::string> out;
    for_each_ray([&](AccelKind, const char* name) { out.push_back(name); });
    return out;
}

std::vector<AccelKind> all_accel_kinds() {
    std::vector<AccelKind> out;
    for_each_ray([&](AccelKind kind, const char*) { out.push_back(kind); });
    return out;
}

std::string to_string(Interpolation i) {
    return i == Interpolation::Nearest ? "nearest" : "trilinear";
}

Interpolation parse_interpolation(const std::string& name) {
    if (name == "trilinear") return Interpolation::Trilinear;
    if (name == "nearest") return Interpolation::Nearest;
    throw FrameError("sampling.interpolation",
                     "unknown '" + name + "'; expected one of: trilinear, nearest");
}

AccelKind default_accel() {
    return AccelKind::Grid;
}

AccelKind parse_accel(const std::string& name) {
    if (name == "auto") return default_accel();
    std::optional<AccelKind> found;
    std::string valid = "auto";
    for_each_ray([&](AccelKind kind, const char* n) {
        if (name == n) found = kind;
        valid += std::string(", ") + n;
    });
    if (!found) throw FrameError("structure", "unknown '" + name + "'; expected one of: " + valid);
    return *found;
}

std::unique_ptr<Accel> make_accel(AccelKind k, const Volume& volume, const AccelOptions& opts) {
    for (const registry::Entry& e : registry::kStructures)
        if (e.ray == k) return e.make_ray(k, volume, opts);
    throw FrameError("structure", "unhandled kind");
}

}  // namespace lacuna
