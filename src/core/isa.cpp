// Which kernel path runs (core/simd_lanes.h): the widest this CPU supports, unless the
// LACUNA_ISA environment variable or set_isa() asks for a narrower one (tests force each path).
#include <atomic>
#include <cstdlib>

#include "core/simd_lanes.h"
#include "lacuna/error.h"

namespace lacuna::simd {

namespace {
struct Name {
    Isa isa;
    const char* name;
};
constexpr Name kNames[] = {
    {Isa::Scalar, "scalar"}, {Isa::Sse41, "sse4.1"}, {Isa::Avx2, "avx2"}, {Isa::Avx512, "avx512"}};

Isa widest() {
    Isa best = Isa::Scalar;
    for (const Name& n : kNames)
        if (isa_supported(n.isa)) best = n.isa;
    return best;
}

Isa initial() {
    Isa i = widest();
    if (const char* env = std::getenv("LACUNA_ISA"); env && *env) {
        const Isa want = parse_isa(env);  // throws with the valid names
        if (int(want) < int(i)) i = want;
    }
    return i;
}

std::atomic<int>& chosen() {
    static std::atomic<int> c{int(initial())};
    return c;
}
}  // namespace

std::string to_string(Isa i) {
    for (const Name& n : kNames)
        if (n.isa == i) return n.name;
    return "?";
}

Isa parse_isa(const std::string& name) {
    std::string valid;
    for (const Name& n : kNames) {
        if (name == n.name) return n.isa;
        valid += (valid.empty() ? "" : ", ") + std::string(n.name);
    }
    throw Error("LACUNA_ISA", "kernel path", "unknown '" + name + "'; expected one of: " + valid);
}

bool isa_supported(Isa i) {
    switch (i) {
        case Isa::Scalar:
            return true;
#if LACUNA_SIMD_X86
#if defined(__SSE4_1__)
        case Isa::Sse41:
            return true;
#else
        case Isa::Sse41:
            return false;
#endif
        case Isa::Avx2:
            return __builtin_cpu_supports("avx2");
        case Isa::Avx512:
            return __builtin_cpu_supports("avx512f");
#else
        default:
            return false;
#endif
    }
    return false;
}

Isa active_isa() {
    return Isa(chosen().load(std::memory_order_relaxed));
}

void set_isa(Isa i) {
    while (!isa_supported(i)) i = Isa(int(i) - 1);
    chosen().store(int(i), std::memory_order_relaxed);
}

int lanes_of(Isa i) {
    switch (i) {
        case Isa::Scalar:
            return 1;
        case Isa::Sse41:
            return 4;
        case Isa::Avx2:
            return 8;
        case Isa::Avx512:
            return 16;
    }
    return 1;
}

}  // namespace lacuna::simd
