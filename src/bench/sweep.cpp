#include "bench/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "accel/cell_ranges.h"
#include "accel/octree.h"
#include "lacuna/error.h"
#include "lacuna/frame_spec.h"
#include "lacuna/session.h"

namespace lacuna::bench {

namespace {

int octree_levels(const Volume& v, int leaf) {
    int cells[3];
    cell_counts(v, cells);
    Pyramid p;
    p.init(cells, leaf);
    return p.levels;
}

// One sweep point: the bitfield octree with `ao` built through the session (timed on its own),
// the orbit rendered through it, view 0 compared with none's; then the octree is dropped.
SweepPoint measure(const BenchDataset& d, Session& session, const std::vector<FrameSpec>& frames,
                   const Image& reference, AccelOptions ao) {
    SweepPoint p;
    p.dataset = d.name;
    p.leaf = ao.leaf_cells;
    p.bits = ao.bitfield_bits;
    p.levels = octree_levels(*d.volume, ao.leaf_cells);
    p.initial_level = ao.initial_level;
    p.bidirectional = ao.bidirectional;
    std::vector<FrameSpec> fs = frames;
    for (FrameSpec& f : fs) f.structure = structure_of(AccelKind::Bitfield, ao);
    const FrameResult built = session.prepare(fs[0]);
    p.generation_ms = (built.build_seconds + built.tf_sync_seconds) * 1e3;
    OrbitRun run = run_orbit(session, fs);
    session.drop_structures();
    std::vector<double> ms;
    for (double s : run.frame_seconds) ms.push_back(s * 1e3);
    p.frame_ms = summarize(ms);
    p.samples = run.samples;
    p.rays = run.rays;
    p.exact = run.first_image.rgba == reference.rgba;
    return p;
}

void log_point(const LogFn& log, const SweepPoint& p) {
    if (!log) return;
    char line[256];
    std::snprintf(line, sizeof line,
                  "  %-16s leaf %2d bits %3d level %2d/%d %-13s mean %8.2f ms  p99 %8.2f ms  "
                  "build %7.1f ms  %6.1f samples/ray  exact %s",
                  p.dataset.c_str(), p.leaf, p.bits,
                  p.initial_level < 0 ? p.levels - 1 : p.initial_level, p.levels - 1,
                  p.bidirectional ? "bidirectional" : "top-down", p.frame_ms.mean, p.frame_ms.p99,
                  p.generation_ms, p.samples_per_ray(), p.exact ? "yes" : "NO");
    log(line);
}

// Geometric mean over datasets of mean / (that dataset's best mean) for each configuration key;
// only keys measured on every dataset compete. Returns the best key.
template <class Key, class KeyFn>
Key best_config(const std::vector<SweepPoint>& pts, const std::vector<std::string>& datasets,
                KeyFn&& key) {
    std::map<std::string, double> best_ms;
    for (const SweepPoint& p : pts)
        if (!best_ms.count(p.dataset) || p.frame_ms.mean < best_ms[p.dataset])
            best_ms[p.dataset] = p.frame_ms.mean;
    std::map<Key, std::pair<double, size_t>> score;  // sum of logs, datasets
    for (const SweepPoint& p : pts) {
        auto& s = score[key(p)];
        s.first += std::log(std::max(p.frame_ms.mean, 1e-9) / std::max(best_ms[p.dataset], 1e-9));
        s.second += 1;
    }
    Key best{};
    double best_score = INFINITY;
    for (const auto& [k, s] : score) {
        if (s.second != datasets.size()) continue;
        if (s.first < best_score) best_score = s.first, best = k;
    }
    return best;
}

}  // namespace

std::vector<std::string> SweepResult::exactness_failures() const {
    std::vector<std::string> out;
    for (const auto* v : {&leaf_bits, &levels})
        for (const SweepPoint& p : *v)
            if (!p.exact)
                out.push_back(p.dataset + " leaf " + std::to_string(p.leaf) + " bits " +
                              std::to_string(p.bits) + " level " + std::to_string(p.initial_level) +
                              (p.bidirectional ? " bidirectional" : " top-down"));
    return out;
}

SweepResult run_sweep(const std::vector<BenchDataset>& datasets, const SweepOptions& o,
                      const LogFn& log) {
    if (o.leaves.empty() || o.bits.empty())
        throw Error("--sweep", "grid", "expected leaf sizes and bit widths");
    SweepResult res;
    res.options = o;
    FrameSpec base;
    base.structure = structure::None{};
    base.sampling.step = o.step;
    base.sampling.early_termination.reset();  // Figures 4 and 6: early ray termination off
    struct Setup {
        std::unique_ptr<Session> session;
        std::vector<FrameSpec> frames;
        Image reference;
    };
    std::vector<Setup> setups;
    for (const BenchDataset& d : datasets) {
        res.datasets.push_back(d.name);
        Setup s;
        s.session = std::make_unique<Session>(*d.volume, o.threads);  // shares the voxels
        s.session->set_transfer_function(d.tf);
        s.frames = orbit_frames(base, o.orbit);
        FrameResult ref = s.session->render(s.frames[0]);
        s.session->drop_structures();
        res.none_ms.push_back(ref.stats.seconds * 1e3);
        s.reference = std::move(ref.image);
        if (log)
            log("sweep " + d.name + ": none view 0 " + fmt("%.1f", ref.stats.seconds * 1e3) +
                " ms");
        setups.push_back(std::move(s));
    }
    // Figure 4: leaf size x bitfield width, from the root, bidirectional.
    for (size_t i = 0; i < datasets.size(); ++i)
        for (int leaf : o.leaves)
            for (int bits : o.bits) {
                AccelOptions ao;
                ao.leaf_cells = leaf;
                ao.bitfield_bits = bits;
                ao.threads = o.threads;
                res.leaf_bits.push_back(measure(datasets[i], *setups[i].session, setups[i].frames,
                                                setups[i].reference, ao));
                log_point(log, res.leaf_bits.back());
            }
    const auto lb = best_config<std::pair<int, int>>(
        res.leaf_bits, res.datasets,
        [](const SweepPoint& p) { return std::make_pair(p.leaf, p.bits); });
    res.best_leaf = lb.first;
    res.best_bits = lb.second;
    if (log)
        log("sweep: best leaf " + std::to_string(res.best_leaf) + ", bits " +
            std::to_string(res.best_bits));
    // Figure 6: every initial level, both traversals, with the best leaf size and width.
    for (size_t i = 0; i < datasets.size(); ++i) {
        const int levels = octree_levels(*datasets[i].volume, res.best_leaf);
        for (int level = levels - 1; level >= 0; --level)
            for (bool bidirectional : {true, false}) {
                AccelOptions ao;
                ao.leaf_cells = res.best_leaf;
                ao.bitfield_bits = res.best_bits;
                ao.initial_level = level;
                ao.bidirectional = bidirectional;
                ao.threads = o.threads;
                res.levels.push_back(measure(datasets[i], *setups[i].session, setups[i].frames,
                                             setups[i].reference, ao));
                log_point(log, res.levels.back());
            }
    }
    const auto lv =
        best_config<std::pair<int, int>>(res.levels, res.datasets, [](const SweepPoint& p) {
            return std::make_pair(p.skipped_levels(), p.bidirectional ? 1 : 0);
        });
    res.best_skipped_levels = lv.first;
    res.best_bidirectional = lv.second == 1;
    return res;
}

std::string sweep_leaf_bits_csv(const SweepResult& r) {
    std::ostringstream out;
    out << "dataset,leaf,bits,levels,initial_level,bidirectional,size,views,mean_ms,p99_ms,"
           "generation_ms,"
           "samples_per_ray,exact\n";
    for (const SweepPoint& p : r.leaf_bits)
        out << p.dataset << ',' << p.leaf << ',' << p.bits << ',' << p.levels << ','
            << p.initial_level << ',' << (p.bidirectional ? 1 : 0) << ',' << r.options.orbit.size
            << ',' << r.options.orbit.views << ',' << fmt("%.4f", p.frame_ms.mean) << ','
            << fmt("%.4f", p.frame_ms.p99) << ',' << fmt("%.4f", p.generation_ms) << ','
            << fmt("%.4f", p.samples_per_ray()) << ',' << (p.exact ? "yes" : "no") << '\n';
    return out.str();
}

std::string sweep_levels_csv(const SweepResult& r) {
    std::ostringstream out;
    out << "dataset,leaf,bits,levels,initial_level,skipped_levels,traversal,size,views,mean_ms,p99_"
           "ms,"
           "generation_ms,samples_per_ray,exact\n";
    for (const SweepPoint& p : r.levels)
        out << p.dataset << ',' << p.leaf << ',' << p.bits << ',' << p.levels << ','
            << p.initial_level << ',' << p.skipped_levels() << ','
            << (p.bidirectional ? "bidirectional" : "top-down") << ',' << r.options.orbit.size
            << ',' << r.options.orbit.views << ',' << fmt("%.4f", p.frame_ms.mean) << ','
            << fmt("%.4f", p.frame_ms.p99) << ',' << fmt("%.4f", p.generation_ms) << ','
            << fmt("%.4f", p.samples_per_ray()) << ',' << (p.exact ? "yes" : "no") << '\n';
    return out.str();
}

std::string sweep_markdown(const SweepResult& r, const RunInfo& info,
                           const std::vector<std::string>& plots) {
    const SweepOptions& o = r.options;
    std::string out =
        "# lacuna bench faludi --sweep: the bitfield octree's parameters (Figures 4 and 6)\n\n";
    out += run_info_markdown(info);
    out += "- Settings: " + std::to_string(o.orbit.size) + "×" + std::to_string(o.orbit.size) +
           " pixels, " + std::to_string(o.orbit.views) + " views, elevation " +
           fmt("%g", o.orbit.elevation_deg) + "°, step " + fmt("%g", o.step) +
           ", early ray termination off (as in both figures), threads " +
           (o.threads > 0 ? std::to_string(o.threads) : "all") + "\n\n";
    out += "## Recommended defaults\n\n";
    out += "Lowest geometric mean over the datasets of (mean frame time ÷ the dataset's best):\n\n";
    out += "- leaf size **" + std::to_string(r.best_leaf) + "³** cells, bitfield width **" +
           std::to_string(r.best_bits) + "** bits\n";
    out += "- initial level: skip **" + std::to_string(r.best_skipped_levels) +
           "** level(s) below the root (AccelOptions::initial_level = levels − 1 − " +
           std::to_string(r.best_skipped_levels) + ")\n";
    out += "- traversal: **" + std::string(r.best_bidirectional ? "bidirectional" : "top-down") +
           "**\n\n";
    const auto failures = r.exactness_failures();
    out += failures.empty() ? "Every sweep point's view 0 equals none's, byte for byte.\n\n"
                            : "**" + std::to_string(failures.size()) +
                                  " sweep point(s) differ from none: a bug.**\n\n";
    for (const std::string& p : plots)
        if (!p.empty()) out += "![" + p + "](" + p + ")\n\n";
    if (plots.empty()) out += "(gnuplot was not found: CSV only, no PNG plots.)\n\n";

    for (size_t di = 0; di < r.datasets.size(); ++di) {
        const std::string& d = r.datasets[di];
        out += "## " + d + " (none, view 0: " + fmt("%.1f", r.none_ms[di]) + " ms)\n\n";
        out +=
            "Figure 4: mean frame time [ms] / generation [ms], traversal from the root.\n\n| leaf "
            "\\ bits |";
        std::string rule = "|---|";
        for (int b : o.bits) out += " " + std::to_string(b) + " |", rule += "---:|";
        out += "\n" + rule + "\n";
        for (int leaf : o.leaves) {
            out += "| " + std::to_string(leaf) + "³ |";
            for (int b : o.bits) {
                std::string cell = "–";
                for (const SweepPoint& p : r.leaf_bits)
                    if (p.dataset == d && p.leaf == leaf && p.bits == b)
                        cell = fmt("%.1f", p.frame_ms.mean) + " / " + fmt("%.0f", p.generation_ms);
                out += " " + cell + " |";
            }
            out += "\n";
        }
        out += "\nFigure 6: mean frame time [ms] by levels skipped below the root (leaf " +
               std::to_string(r.best_leaf) + "³, " + std::to_string(r.best_bits) +
               " bits).\n\n| skipped | initial level | bidirectional | top-down "
               "|\n|---:|---:|---:|---:|\n";
        for (const SweepPoint& p : r.levels) {
            if (p.dataset != d || !p.bidirectional) continue;
            std::string td = "–";
            for (const SweepPoint& q : r.levels)
                if (q.dataset == d && !q.bidirectional && q.initial_level == p.initial_level)
                    td = fmt("%.1f", q.frame_ms.mean);
            out += "| " + std::to_string(p.skipped_levels()) + " | " +
                   std::to_string(p.initial_level) + " | " + fmt("%.1f", p.frame_ms.mean) + " | " +
                   td + " |\n";
        }
        out += "\n";
    }
    return out;
}

}  // namespace lacuna::bench
