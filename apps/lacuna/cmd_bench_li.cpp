// `lacuna bench li`: the growing-boxes paper's Tables 1 and 2 with the slice renderer
// (src/bench/li.h). Flags become typed options here.
#include <cstdio>
#include <filesystem>

#include "bench/datasets.h"
#include "bench/li.h"
#include "bench/plot.h"
#include "bench/report.h"
#include "bench_cli.h"
#include "cli_common.h"
#include "lacuna/error.h"
#include "slice/box_sources.h"

namespace lacuna::cli {

namespace {

struct LiArgs {
    int size = 384, views = 8;
    float elevation = 20.f;
    std::string datasets = "ch2-skin,ch2bet-brain,ch2better-brain,aal,tree512";
    std::string ess = "boxes";
    float step = 0.5f, threshold = 0.95f;
    int map = 64, updates = 9, threads = 0, updates_views = 60;
    float coalesce = BoxesOptions{}.coalesce;
    float coalesce_edge = BoxesOptions{}.coalesce_edge;
    bool no_march = false;
    std::string out_dir = "out/bench";
    std::string templates = bench::DatasetSource{}.templates_dir;
};

void run_li(const LiArgs& a) {
    bench::LiOptions o;
    o.orbit.size = a.size;
    o.orbit.views = a.views;
    o.orbit.elevation_deg = a.elevation;
    if (a.size < 1 || a.size > 16384) throw Error("--size", "image size", "expected 1..16384");
    if (a.views < 1) throw Error("--views", "views", "expected at least 1");
    if (!(a.step > 0.f && a.step <= 64.f)) throw Error("--step", "step", "expected 0 < step <= 64");
    if (!(a.threshold > 0.f && a.threshold <= 1.f))
        throw Error("--threshold", "threshold", "expected 0 < T <= 1");
    if (a.map < 1 || a.map > 4096) throw Error("--map", "map size", "expected 1..4096");
    if (a.updates < 0 || a.updates > 1000) throw Error("--updates", "updates", "expected 0..1000");
    if (a.ess != "kdtree" && a.ess != "boxes")
        throw Error("--ess", "box source", "expected kdtree or boxes, got '" + a.ess + "'");
    o.ess = a.ess;
    o.boxes.coalesce = a.coalesce;
    o.boxes.coalesce_edge = a.coalesce_edge;
    o.step = a.step;
    o.threshold = a.threshold;
    o.map_size = a.map;
    o.initial_updates = a.updates;
    if (a.updates_views < 0) throw Error("--updates-views", "views", "expected >= 0");
    o.updates_views = a.updates_views;
    o.threads = a.threads;
    o.march = !a.no_march;
    o.accel.threads = a.threads;
    std::vector<bench::DatasetId> ids;
    for (const std::string& n : split_list(a.datasets)) ids.push_back(bench::parse_dataset(n));
    if (ids.empty()) throw Error("--datasets", "datasets", "expected at least one");
    const std::filesystem::path dir = create_out_dir(a.out_dir);
    bench::RunInfo info =
        bench::collect_run_info(command_line("lacuna bench li", ArgQuoting::Plain));
    std::printf("lacuna bench li: %dx%d, %d views, %zu datasets, ESS = %s, %s, %d threads\n",
                a.size, a.size, a.views, ids.size(), a.ess.c_str(), info.cpu.c_str(), info.cores);
    bench::DatasetSource src;
    src.templates_dir = a.templates;
    src.threads = a.threads;
    const auto datasets = bench::load_datasets(ids, src, log_line);
    const bench::LiReport rep = bench::run_li(datasets, o, log_line);
    info.load_end = bench::current_load();
    const std::string md = bench::li_markdown(rep, info);
    bench::write_text_file((dir / "li.md").string(), md);
    bench::write_text_file((dir / "li.csv").string(), bench::li_csv(rep));
    bench::write_text_file((dir / "li-updates.csv").string(), bench::li_updates_csv(rep));
    std::string plot = ", no plot (gnuplot not found)";
    if (!rep.figure6.desired.empty() && bench::gnuplot_available()) {
        bench::run_gnuplot(bench::li_updates_gnuplot(rep, (dir / "li-updates.png").string()));
        plot = ", li-updates.png";
    }
    std::printf("\n%s\nwrote li.md, li.csv, li-updates.csv%s in %s\n", md.c_str(), plot.c_str(),
                dir.c_str());
    for (const auto& d : rep.datasets)
        if (!d.ess_exact || !d.map_only_exact)
            throw Error("bench li", "exactness",
                        d.name + ": ESS or ESS+M differs from Basic (a bug)");
}

}  // namespace

void register_bench_li(CLI::App& bench) {
    auto a = std::make_shared<LiArgs>();
    auto* c = bench.add_subcommand(
        "li", "The growing-boxes paper's Tables 1 and 2 with the slice renderer (docs/slicer.md)");
    std::string names;
    for (const auto& n : bench::dataset_names()) names += (names.empty() ? "" : ",") + n;
    c->add_option("--size", a->size, "Image width and height in pixels")->capture_default_str();
    c->add_option("--views", a->views, "Views in the orbit")->capture_default_str();
    c->add_option("--elevation", a->elevation, "Orbit elevation in degrees")->capture_default_str();
    c->add_option("--datasets", a->datasets, "Comma-separated datasets: " + names)
        ->capture_default_str();
    c->add_option("--ess", a->ess, "Box source of the ESS columns: kdtree or boxes")
        ->capture_default_str();
    c->add_option("--coalesce", a->coalesce,
                  "ESS boxes: a BSP subtree at most this share empty is one box (negative: off)")
        ->capture_default_str();
    c->add_option("--coalesce-edge", a->coalesce_edge,
                  "ESS boxes: largest joined box, per axis in world units (mm)")
        ->capture_default_str();
    c->add_option("--step", a->step, "Slice distance in voxels")->capture_default_str();
    c->add_option("--threshold", a->threshold, "Occlusion opacity threshold")
        ->capture_default_str();
    c->add_option("--map", a->map, "Opacity map edge in cells")->capture_default_str();
    c->add_option("--updates", a->updates, "Initial desired map updates per frame (k)")
        ->capture_default_str();
    c->add_option("--updates-views", a->updates_views,
                  "Figure 6: ESS+CC frames of a longer orbit on the first dataset (0 = none)")
        ->capture_default_str();
    c->add_option("--threads", a->threads, "Threads (0 = all)")->capture_default_str();
    c->add_flag("--no-march", a->no_march, "Skip the ray-marcher columns");
    c->add_option("--out-dir", a->out_dir, "Folder for li.md and the CSV files")
        ->capture_default_str();
    c->add_option("--templates", a->templates, "Folder of the mricron templates")
        ->capture_default_str();
    c->callback([a] { with_summary("bench li", [&] { run_li(*a); }); });
}

}  // namespace lacuna::cli
