// splitmix64: the one deterministic PRNG of the test suite (std distributions differ between
// standard libraries, so randomized cases would not reproduce across machines).
#pragma once
#include <cstdint>

namespace lacuna::test {

struct Rng {
    uint64_t s;
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uniform() { return float(next() >> 40) / float(1 << 24); }  // [0, 1)
    double uniform_d() { return double(next() >> 11) / double(uint64_t(1) << 53); }
    int range(int lo, int hi) { return lo + int(next() % uint64_t(int64_t(hi) - lo + 1)); }
    bool coin(int one_in = 2) { return next() % uint64_t(one_in) == 0; }
};

}  // namespace lacuna::test
