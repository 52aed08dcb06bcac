// `lacuna bench kdtree`: flags to typed options for src/bench/kdtree_bench.h (docs/kdtree.md,
// docs/benchmarks.md).
#include <cstdio>
#include <filesystem>
#include <memory>

#include "bench/kdtree_bench.h"
#include "bench/report.h"
#include "bench_cli.h"
#include "cli_common.h"
#include "lacuna/error.h"

namespace lacuna::cli {

namespace {

struct KdBenchArgs {
    std::string datasets = "ch2,ch2better,ch2bet,aal,tree";
    std::string sizes = "256,512";
    std::string max_boxes = "1,2,4,8,16,32,all";
    int size = 256, views = 4, repeat = 5, threads = 0;
    float elevation = 20.f, step = 0.5f, ert = 0.99f;
    int delta = 0, max_depth = 10;
    float min_volume = 0.1f, min_gain = 0.05f;
    std::string templates = bench::DatasetSource{}.templates_dir;
    std::string out_dir = "out/bench";
    bool quick = false;
};

void run_kdtree_bench(const KdBenchArgs& a) {
    bench::KdBenchOptions o;
    o.datasets.clear();
    for (const std::string& n : split_list(a.datasets))
        o.datasets.push_back(bench::parse_kd_dataset(n, "--datasets"));
    if (o.datasets.empty()) throw Error("--datasets", "list", "expected at least one dataset");
    o.sizes.clear();
    for (const std::string& n : split_list(a.sizes)) {
        o.sizes.push_back(parse_count(n, "--sizes", a.sizes));
        if (o.sizes.back() < 3 || o.sizes.back() > 1024)
            throw Error("--sizes", "size", "expected 3..1024, got " + n);
    }
    o.max_boxes.clear();
    for (const std::string& n : split_list(a.max_boxes)) {
        const int m = n == "all" ? 0 : parse_count(n, "--max-boxes", a.max_boxes);
        if (n != "all" && m < 1)
            throw Error("--max-boxes", "M", "expected M >= 1 or 'all', got '" + n + "'");
        o.max_boxes.push_back(m);
    }
    if (o.max_boxes.empty()) throw Error("--max-boxes", "list", "expected at least one M");
    if (a.size < 1 || a.size > 16384) throw Error("--size", "image size", "expected 1..16384");
    if (a.views < 1) throw Error("--views", "views", "expected at least 1");
    if (a.repeat < 1 || a.repeat > 1000) throw Error("--repeat", "builds", "expected 1..1000");
    if (!(a.step > 0.f && a.step <= 64.f)) throw Error("--step", "step", "expected 0 < step <= 64");
    if (!(a.ert > 0.f)) throw Error("--ert", "threshold", "expected > 0 (>= 1 turns it off)");
    o.orbit.size = a.size;
    o.orbit.views = a.views;
    o.orbit.elevation_deg = a.elevation;
    o.step = a.step;
    o.ert = a.ert;
    o.repeats = a.repeat;
    o.threads = a.threads;
    o.accel.kd_delta = a.delta;
    o.accel.kd_min_volume = a.min_volume;
    o.accel.kd_min_gain = a.min_gain;
    o.accel.kd_max_depth = a.max_depth;
    o.accel.threads = a.threads;
    kd_settings(o.accel);  // validates the kd options before any work
    o.source.templates_dir = a.templates;
    o.source.threads = a.threads;

    const std::filesystem::path dir = create_out_dir(a.out_dir);
    bench::RunInfo info = bench::collect_run_info(command_line("lacuna bench kdtree"));
    std::printf(
        "lacuna bench kdtree: %zu datasets x %zu sizes, %dx%d px, %d views, %s, %d threads\n",
        o.datasets.size(), o.sizes.size(), o.orbit.size, o.orbit.size, o.orbit.views,
        info.cpu.c_str(), info.cores);
    const std::string md_path = (dir / "kdtree.md").string(),
                      csv_path = (dir / "kdtree.csv").string();
    auto write = [&](const bench::KdBenchReport& rep) {
        info.load_end = bench::current_load();
        bench::write_text_file(md_path, bench::kd_bench_markdown(rep, info));
        bench::write_text_file(csv_path, bench::kd_bench_csv(rep));
    };
    const bench::KdBenchReport rep = bench::run_kd_bench(o, log_line, write);
    write(rep);
    std::printf("\n%s\nwrote %s and %s\n", bench::kd_bench_markdown(rep, info).c_str(),
                md_path.c_str(), csv_path.c_str());
    const auto failures = rep.exactness_failures();
    if (!failures.empty()) {
        std::string list;
        for (const auto& f : failures) list += (list.empty() ? "" : "; ") + f;
        throw Error(
            "bench kdtree", "exactness",
            std::to_string(failures.size()) + " image(s) differ from none (a bug): " + list);
    }
}

}  // namespace

void register_bench_kdtree(CLI::App& bench) {
    auto a = std::make_shared<KdBenchArgs>();
    auto* k = bench.add_subcommand(
        "kdtree",
        "The kd-tree paper's measurements: boxes, removed space, steps 1-3, frames per M");
    k->add_option("--datasets", a->datasets,
                  "Comma-separated: ch2, ch2better, ch2bet, aal, tree (or faludi names)")
        ->capture_default_str();
    k->add_option("--sizes", a->sizes, "Each dataset at n^3 (templates resampled, trees generated)")
        ->capture_default_str();
    k->add_option("--max-boxes", a->max_boxes, "List limits M ('all' = every leaf)")
        ->capture_default_str();
    k->add_option("--size", a->size, "Image width and height in pixels")->capture_default_str();
    k->add_option("--views", a->views, "Views in the orbit")->capture_default_str();
    k->add_option("--elevation", a->elevation, "Orbit elevation in degrees")->capture_default_str();
    k->add_option("--repeat", a->repeat, "Preprocessing builds per dataset (medians)")
        ->capture_default_str();
    k->add_option("--threads", a->threads, "Build and render threads (0 = all)")
        ->capture_default_str();
    k->add_option("--step", a->step, "Sample distance in units of the smallest spacing")
        ->capture_default_str();
    k->add_option("--ert", a->ert, "Early ray termination opacity (>= 1: off)")
        ->capture_default_str();
    k->add_option("--delta", a->delta, "Candidate plane spacing in cells (0 = from the size)")
        ->capture_default_str();
    k->add_option("--min-volume", a->min_volume, "Halting: nodes below this fraction are leaves")
        ->capture_default_str();
    k->add_option("--min-gain", a->min_gain, "Halting: a split must remove this fraction")
        ->capture_default_str();
    k->add_option("--max-depth", a->max_depth, "Halting: deepest level")->capture_default_str();
    k->add_option("--templates", a->templates, "Folder of the mricron templates")
        ->capture_default_str();
    k->add_option("--out-dir", a->out_dir, "Folder for kdtree.md and kdtree.csv")
        ->capture_default_str();
    k->add_flag(
        "--quick", a->quick,
        "Tiny run: ch2bet and tree at 24^3 and 40^3, 48 px, 1 view, 1 build (unless given)");
    k->callback([a, k] {
        KdBenchArgs args = *a;
        if (args.quick) {
            if (!k->count("--datasets")) args.datasets = "ch2bet,tree";
            if (!k->count("--sizes")) args.sizes = "24,40";
            if (!k->count("--size")) args.size = 48;
            if (!k->count("--views")) args.views = 1;
            if (!k->count("--repeat")) args.repeat = 1;
        }
        with_summary("bench kdtree", [&] { run_kdtree_bench(args); });
    });
}

}  // namespace lacuna::cli
