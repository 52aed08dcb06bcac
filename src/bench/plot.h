// PNG plots of the sweep through gnuplot (Debian package gnuplot-nox), when it is on PATH.
// The data goes inline into the script (gnuplot datablocks), so no temporary files are left.
#pragma once
#include <string>

#include "bench/sweep.h"

namespace lacuna::bench {

// True when an executable `gnuplot` is on PATH.
bool gnuplot_available();

// Figure 4: per dataset, clustered bars of mean frame time, samples per ray (deterministic: how
// well the tree skips, whatever the machine's load) and generation time by leaf size, one bar
// per bitfield width.
std::string leaf_bits_gnuplot(const SweepResult& r, const std::string& png_path);
// Figure 6: per dataset, mean frame time by levels skipped below the root; solid bidirectional,
// dashed top-down.
std::string levels_gnuplot(const SweepResult& r, const std::string& png_path);

// Runs a gnuplot script. Throws lacuna::Error("gnuplot", ...) when gnuplot fails.
void run_gnuplot(const std::string& script);

}  // namespace lacuna::bench
