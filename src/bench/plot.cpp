#include "bench/plot.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "lacuna/error.h"

namespace lacuna::bench {

namespace {

// gnuplot single-quoted string: a quote is doubled.
std::string quoted(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

std::string title_text(const std::string& s) {
    std::string out;
    for (char c : s) out += c == '_' ? std::string("\\\\_") : std::string(1, c);
    return out;
}

}  // namespace

bool gnuplot_available() {
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::stringstream dirs(path);
    for (std::string dir; std::getline(dirs, dir, ':');) {
        if (dir.empty()) continue;
        std::error_code ec;
        const auto p = std::filesystem::path(dir) / "gnuplot";
        const auto st = std::filesystem::status(p, ec);
        if (!ec && std::filesystem::is_regular_file(st) &&
            (st.permissions() & std::filesystem::perms::others_exec) !=
                std::filesystem::perms::none)
            return true;
    }
    return false;
}

std::string leaf_bits_gnuplot(const SweepResult& r, const std::string& png) {
    const auto& o = r.options;
    std::ostringstream s;
    const size_t n = r.datasets.size();
    s << "set terminal pngcairo size 1200," << 300 * n << " font ',9'\n";
    s << "set output " << quoted(png) << "\n";
    s << "set style data histograms\nset style histogram clustered gap 1\n"
         "set style fill solid 0.85 border -1\nset boxwidth 0.9\nset grid ytics\n"
         "set key inside top center horizontal maxrows 1 font ',8' samplen 1.5\n"
         "set yrange [0:*]\nset offsets 0, 0, graph 0.15, 0\n"
         "set xlabel 'Leaf block size [cells^3]'\n";
    s << "set multiplot layout " << n << ",3 title 'Bitfield octree: leaf size x bitfield width ("
      << o.orbit.size << "^2, " << o.orbit.views << " views, no early exit)'\n";
    for (size_t di = 0; di < n; ++di) {
        const std::string& d = r.datasets[di];
        for (int which = 0; which < 3; ++which) {
            s << "$d" << di << "_" << which << " << EOD\nleaf";
            for (int b : o.bits) s << " " << b << "-bit";
            s << "\n";
            for (int leaf : o.leaves) {
                s << leaf;
                for (int b : o.bits) {
                    double v = 0;
                    for (const SweepPoint& p : r.leaf_bits)
                        if (p.dataset == d && p.leaf == leaf && p.bits == b)
                            v = which == 0   ? p.frame_ms.mean
                                : which == 1 ? p.samples_per_ray()
                                             : p.generation_ms;
                    s << " " << v;
                }
                s << "\n";
            }
            s << "EOD\n";
            const char* titles[3] = {": mean frame time", ": samples per ray", ": generation time"};
            const char* labels[3] = {"Frame time [ms]", "Samples per ray", "Generation [ms]"};
            s << "set title " << quoted(title_text(d) + titles[which]) << "\n";
            s << "set ylabel " << quoted(labels[which]) << "\n";
            s << "plot for [c=2:" << o.bits.size() + 1 << "] $d" << di << "_" << which
              << " using c:xtic(1) title columnheader(c)\n";
        }
    }
    s << "unset multiplot\n";
    return s.str();
}

std::string levels_gnuplot(const SweepResult& r, const std::string& png) {
    const auto& o = r.options;
    std::ostringstream s;
    const size_t n = r.datasets.size();
    s << "set terminal pngcairo size " << 450 * n << ",340 font ',9'\n";
    s << "set output " << quoted(png) << "\n";
    s << "set grid\nset key top right font ',8'\nset yrange [0:*]\n"
         "set xlabel 'Octree levels skipped below the root'\nset ylabel 'Mean frame time [ms]'\n";
    s << "set multiplot layout 1," << n << " title 'Bitfield octree: initial level, leaf "
      << r.best_leaf << "^3, " << r.best_bits << " bits (" << o.orbit.size << "^2, "
      << o.orbit.views << " views, no early exit)'\n";
    for (size_t di = 0; di < n; ++di) {
        const std::string& d = r.datasets[di];
        for (int bi = 0; bi < 2; ++bi) {
            s << "$l" << di << "_" << bi << " << EOD\n";
            for (const SweepPoint& p : r.levels)
                if (p.dataset == d && p.bidirectional == (bi == 0))
                    s << p.skipped_levels() << " " << p.frame_ms.mean << "\n";
            s << "EOD\n";
        }
        s << "set title " << quoted(title_text(d)) << "\nset xtics 1\n";
        s << "plot $l" << di
          << "_0 using 1:2 with linespoints lw 2 pt 7 dt 1 lc 1 title 'bidirectional', "
          << "$l" << di << "_1 using 1:2 with linespoints lw 2 pt 6 dt 2 lc 2 title 'top-down'\n";
    }
    s << "unset multiplot\n";
    return s.str();
}

void run_gnuplot(const std::string& script) {
    FILE* p = popen("gnuplot", "w");
    if (!p) throw Error("gnuplot", "run", "cannot start gnuplot");
    const size_t written = std::fwrite(script.data(), 1, script.size(), p);
    const int rc = pclose(p);
    if (written != script.size() || rc != 0)
        throw Error("gnuplot", "run", "gnuplot failed (exit status " + std::to_string(rc) + ")");
}

}  // namespace lacuna::bench
