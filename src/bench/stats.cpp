#include "bench/stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lacuna::bench {

std::string to_string(const Summary& s) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "n %zu, mean %.4g, p99 %.4g, min %.4g, max %.4g", s.n, s.mean,
                  s.p99, s.min, s.max);
    return buf;
}

double mean(const std::vector<double>& values) {
    if (values.empty()) return 0;
    double sum = 0;
    for (double v : values) sum += v;
    return sum / double(values.size());
}

double percentile(std::vector<double> values, double p) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const double n = double(values.size());
    // Rank in 1..n; the small epsilon keeps p = 50, n = 10 at rank 5 despite rounding.
    size_t rank = size_t(std::ceil(p / 100.0 * n - 1e-9));
    rank = std::clamp<size_t>(rank, 1, values.size());
    return values[rank - 1];
}

Summary summarize(const std::vector<double>& values) {
    Summary s;
    s.n = values.size();
    if (values.empty()) return s;
    s.mean = mean(values);
    s.p99 = percentile(values, 99);
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    s.min = *lo;
    s.max = *hi;
    return s;
}

}  // namespace lacuna::bench
