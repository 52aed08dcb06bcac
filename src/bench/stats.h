// Summary statistics of benchmark samples (frame times).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace lacuna::bench {

struct Summary {
    size_t n = 0;
    double mean = 0, p99 = 0, min = 0, max = 0;
};
std::string to_string(const Summary& s);

// Arithmetic mean; 0 for no values.
double mean(const std::vector<double>& values);
// Nearest-rank percentile, p in (0, 100]: the smallest value v such that at least p% of the
// values are <= v, i.e. the ceil(p/100 * n)-th smallest. For n < 100, p99 is the maximum: with 36
// views "the slowest 1 percentile" (the paper's measure) is the slowest frame. 0 for no values.
double percentile(std::vector<double> values, double p);
Summary summarize(const std::vector<double>& values);

}  // namespace lacuna::bench
