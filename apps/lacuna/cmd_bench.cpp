// `lacuna bench ...`: reproducible benchmarks (docs/benchmarks.md). This file only turns flags
// into typed options; the benchmarks live in src/bench/.
#include <cstdio>
#include <filesystem>

#include "bench/datasets.h"
#include "bench/faludi.h"
#include "bench/plot.h"
#include "bench/report.h"
#include "bench/sweep.h"
#include "bench_cli.h"
#include "cli_common.h"
#include "lacuna/error.h"

namespace lacuna::cli {

namespace {

struct FaludiArgs {
    int size = 1024, views = 36;
    float elevation = 20.f;
    std::string datasets;  // default: all
    std::string accels;    // default: all
    int threads = 0;
    std::string out_dir = "out/bench";
    bool quick = false;
    bool sweep = false;
    std::string sweep_datasets = "ch2better-gap,tree512";
    std::string sweep_leaves = "2,4,8,16,32,64";
    std::string sweep_bits = "8,16,32,64,128";
    std::string templates = bench::DatasetSource{}.templates_dir;
    int tree_size = 512;
    int leaf = 8, bits = 64, initial_level = -1;
    bool top_down = false;
    float step = 0.5f, ert = 0.99f;
    int tf_repeats = 3;
    bool no_ideal = false;
    bool no_refine = false;
    bool size_given = false, views_given = false;
    std::string rows = "marching,early-exit";  // --rows: also shading, lighting
    float shadow_step = 1.f;
    std::string interpolation = "trilinear";
};

std::vector<int> parse_int_list(const std::string& s, const std::string& where) {
    std::vector<int> out;
    for (const std::string& item : split_list(s)) out.push_back(parse_count(item, where, s));
    if (out.empty()) throw Error(where, "list", "expected at least one value");
    return out;
}

// Runs a parser whose errors name another option (--datasets, --accel) under `where`'s name.
template <class F>
auto with_option(const std::string& where, F&& parse) {
    try {
        return parse();
    } catch (const Error& e) {
        const std::string what = e.what();
        const size_t colon = what.find(": ");
        throw Error(where + (colon == std::string::npos ? ": " + what : what.substr(colon)));
    }
}

std::vector<bench::DatasetId> parse_datasets(const std::string& s, const std::string& where) {
    std::vector<bench::DatasetId> out;
    if (s.empty()) return bench::all_datasets();
    for (const std::string& name : split_list(s)) {
        out.push_back(with_option(where, [&] { return bench::parse_dataset(name); }));
    }
    return out;
}

void run_table(const FaludiArgs& a, const bench::OrbitSpec& orbit, const AccelOptions& ao,
               const std::filesystem::path& dir) {
    bench::FaludiOptions fo;
    fo.orbit = orbit;
    if (!a.accels.empty()) {
        fo.accels.clear();
        for (const std::string& n : split_list(a.accels))
            fo.accels.push_back(with_option("--accels", [&] { return parse_accel(n); }));
    }
    fo.accel = ao;
    fo.step = a.step;
    fo.ert = a.ert;
    fo.threads = a.threads;
    fo.tf_repeats = a.tf_repeats;
    fo.ideal = !a.no_ideal;
    fo.refine = !a.no_refine;
    fo.modes.clear();
    for (const std::string& n : split_list(a.rows)) fo.modes.push_back(bench::parse_row_mode(n));
    if (!(a.shadow_step > 0.f && a.shadow_step <= 64.f))
        throw Error("--shadow-step", "step", "expected 0 < step <= 64");
    fo.shadow_step = a.shadow_step;
    fo.interpolation = parse_interpolation(a.interpolation);
    const auto ids = parse_datasets(a.datasets, "--datasets");
    bench::RunInfo info = bench::collect_run_info(command_line("lacuna bench faludi"));
    std::printf("lacuna bench faludi: %dx%d, %d views, %zu datasets, %s, %d threads\n", orbit.size,
                orbit.size, orbit.views, ids.size(), info.cpu.c_str(), info.cores);
    bench::DatasetSource src;
    src.templates_dir = a.templates;
    src.tree_size = a.tree_size;
    src.threads = a.threads;
    const auto datasets = bench::load_datasets(ids, src, log_line);
    auto write = [&](const bench::FaludiReport& rep) {
        info.load_end = bench::current_load();
        bench::write_text_file((dir / "faludi.md").string(), bench::faludi_markdown(rep, info));
        bench::write_text_file((dir / "faludi.csv").string(), bench::faludi_csv(rep));
    };
    const bench::FaludiReport rep = bench::run_faludi(datasets, fo, log_line, write);
    write(rep);
    const std::string md = bench::faludi_markdown(rep, info);
    std::printf("\n%s\nwrote %s and %s\n", md.c_str(), (dir / "faludi.md").c_str(),
                (dir / "faludi.csv").c_str());
    const auto failures = rep.exactness_failures();
    if (!failures.empty()) {
        std::string list;
        for (const auto& f : failures) list += (list.empty() ? "" : "; ") + f;
        std::fprintf(stderr, "\n!!! EXACTNESS FAILURE: %zu cell(s) differ from none: %s\n",
                     failures.size(), list.c_str());
        throw Error(
            "bench faludi", "exactness",
            std::to_string(failures.size()) + " structure image(s) differ from none (a bug)");
    }
}

void run_sweep(const FaludiArgs& a, const bench::OrbitSpec& orbit,
               const std::filesystem::path& dir) {
    bench::SweepOptions so;
    so.orbit = orbit;
    so.leaves = parse_int_list(a.sweep_leaves, "--sweep-leaves");
    so.bits = parse_int_list(a.sweep_bits, "--sweep-bits");
    so.step = a.step;
    so.threads = a.threads;
    const auto ids = parse_datasets(a.sweep_datasets, "--sweep-dataset");
    bench::RunInfo info = bench::collect_run_info(command_line("lacuna bench faludi"));
    std::printf("lacuna bench faludi --sweep: %dx%d, %d views, %zu datasets, %s, %d threads\n",
                orbit.size, orbit.size, orbit.views, ids.size(), info.cpu.c_str(), info.cores);
    bench::DatasetSource src;
    src.templates_dir = a.templates;
    src.tree_size = a.tree_size;
    src.threads = a.threads;
    const auto datasets = bench::load_datasets(ids, src, log_line);
    const bench::SweepResult res = bench::run_sweep(datasets, so, log_line);
    info.load_end = bench::current_load();
    bench::write_text_file((dir / "sweep-leaf-bits.csv").string(), bench::sweep_leaf_bits_csv(res));
    bench::write_text_file((dir / "sweep-levels.csv").string(), bench::sweep_levels_csv(res));
    std::vector<std::string> plots;
    if (bench::gnuplot_available()) {
        const std::string fig4 = "bench-sweep-leaf-bits.png", fig6 = "bench-sweep-levels.png";
        bench::run_gnuplot(bench::leaf_bits_gnuplot(res, (dir / fig4).string()));
        bench::run_gnuplot(bench::levels_gnuplot(res, (dir / fig6).string()));
        plots = {fig4, fig6};
    } else {
        std::printf(
            "gnuplot not found on PATH: writing CSV only (install gnuplot-nox for PNG plots)\n");
    }
    const std::string md = bench::sweep_markdown(res, info, plots);
    bench::write_text_file((dir / "sweep.md").string(), md);
    std::printf("\n%s\nwrote %s (and CSV%s) in %s\n", md.c_str(), "sweep.md",
                plots.empty() ? "" : ", PNG", dir.c_str());
    std::printf("recommended defaults: leaf %d, bits %d, skip %d level(s) below the root, %s\n",
                res.best_leaf, res.best_bits, res.best_skipped_levels,
                res.best_bidirectional ? "bidirectional" : "top-down");
    const auto failures = res.exactness_failures();
    if (!failures.empty()) {
        std::fprintf(stderr, "\n!!! EXACTNESS FAILURE: %zu sweep point(s) differ from none\n",
                     failures.size());
        throw Error("bench faludi --sweep", "exactness",
                    std::to_string(failures.size()) + " image(s) differ from none (a bug)");
    }
}

void run_faludi(FaludiArgs& a) {
    bench::OrbitSpec orbit;
    orbit.size = a.quick && !a.size_given ? 256 : a.size;
    orbit.views = a.quick && !a.views_given ? 6 : a.views;
    orbit.elevation_deg = a.elevation;
    if (orbit.size < 1 || orbit.size > 16384)
        throw Error("--size", "image size", "expected 1..16384");
    if (orbit.views < 1) throw Error("--views", "views", "expected at least 1");
    if (!(a.step > 0.f && a.step <= 64.f)) throw Error("--step", "step", "expected 0 < step <= 64");
    if (!(a.ert > 0.f && a.ert < 1.f)) throw Error("--ert", "threshold", "expected 0 < ert < 1");
    if (a.tree_size < 2 || a.tree_size > 4096)
        throw Error("--tree-size", "size", "expected 2..4096");
    AccelOptions ao;
    ao.leaf_cells = a.leaf;
    ao.bitfield_bits = a.bits;
    ao.initial_level = a.initial_level;
    ao.bidirectional = !a.top_down;
    ao.threads = a.threads;
    const std::filesystem::path dir = create_out_dir(a.out_dir);
    if (a.sweep)
        run_sweep(a, orbit, dir);
    else
        run_table(a, orbit, ao, dir);
}

}  // namespace

void register_bench_kdtree(CLI::App& bench);  // cmd_bench_kdtree.cpp

void register_bench(CLI::App& app) {
    auto* cmd = app.add_subcommand("bench", "Benchmarks (docs/benchmarks.md)");
    cmd->require_subcommand(1);
    register_bench_kdtree(*cmd);
    void register_bench_li(CLI::App&);  // cmd_bench_li.cpp
    register_bench_li(*cmd);
    void register_bench_vtk(CLI::App&);  // cmd_bench_vtk.cpp
    register_bench_vtk(*cmd);
    void register_bench_mpi(CLI::App&);  // bench_mpi.cpp (in the executable: it uses src/dist/)
    register_bench_mpi(*cmd);

    auto a = std::make_shared<FaludiArgs>();
    auto* f = cmd->add_subcommand(
        "faludi", "The bitfield paper's Table 1 (and, with --sweep, Figures 4 and 6) on our data");
    std::string datasets, accels;
    for (const auto& n : bench::dataset_names()) datasets += (datasets.empty() ? "" : ",") + n;
    for (const auto& n : accel_names()) accels += (accels.empty() ? "" : ",") + n;
    f->add_option("--size", a->size, "Image width and height in pixels")->capture_default_str();
    f->add_option("--views", a->views, "Views in the orbit (azimuth 360*i/views)")
        ->capture_default_str();
    f->add_option("--elevation", a->elevation, "Orbit elevation in degrees")->capture_default_str();
    f->add_option("--datasets", a->datasets, "Comma-separated datasets (default all): " + datasets);
    f->add_option("--accels", a->accels,
                  "Comma-separated structures (default all; none always runs): " + accels);
    f->add_option("--threads", a->threads, "Render and build threads (0 = all)")
        ->capture_default_str();
    f->add_option("--out-dir", a->out_dir, "Folder for markdown, CSV and plots")
        ->capture_default_str();
    f->add_flag("--quick", a->quick, "Smoke run: --size 256 --views 6 unless given");
    f->add_flag("--sweep", a->sweep, "Parameter sweep (Figures 4 and 6) instead of the table");
    f->add_option("--sweep-dataset", a->sweep_datasets, "Comma-separated datasets for --sweep")
        ->capture_default_str();
    f->add_option("--sweep-leaves", a->sweep_leaves, "Leaf sizes for --sweep")
        ->capture_default_str();
    f->add_option("--sweep-bits", a->sweep_bits, "Bitfield widths for --sweep")
        ->capture_default_str();
    f->add_option("--templates", a->templates, "Folder of the mricron templates")
        ->capture_default_str();
    f->add_option("--tree-size", a->tree_size, "Edge of the generated tree volume")
        ->capture_default_str();
    f->add_option("--leaf", a->leaf, "Octree leaf edge in cells")->capture_default_str();
    f->add_option("--bits", a->bits, "Bitfield width")->capture_default_str();
    f->add_option("--initial-level", a->initial_level, "Octree initial level (-1 = root)")
        ->capture_default_str();
    f->add_flag("--top-down", a->top_down, "Octree traversal restarts at the initial level");
    f->add_option("--step", a->step, "Sample distance in units of the smallest spacing")
        ->capture_default_str();
    f->add_option("--ert", a->ert, "Early ray termination opacity of the '+ early exit' rows")
        ->capture_default_str();
    f->add_option("--tf-repeats", a->tf_repeats, "TF changes timed per structure (median)")
        ->capture_default_str();
    f->add_flag("--no-ideal", a->no_ideal, "Skip the ideal-speedup sample count");
    f->add_flag("--no-refine", a->no_refine,
                "Time each structure without its finer per-TF level (Accel::refine), as right "
                "after a TF edit");
    f->add_option("--rows", a->rows,
                  "Comma-separated rows: marching, early-exit, shading (+ PBR shading), lighting "
                  "(+ spotlight with shadow rays)")
        ->capture_default_str();
    f->add_option(
         "--interpolation", a->interpolation,
         "Sampling of every row: trilinear, or nearest (structures built for it; the ideal "
         "counts samples whose voxel is visible)")
        ->capture_default_str();
    f->add_option("--shadow-step", a->shadow_step, "Shadow-ray sample distance of the lighting row")
        ->capture_default_str();
    f->callback([a, f] {
        a->size_given = f->count("--size") > 0;
        a->views_given = f->count("--views") > 0;
        with_summary("bench faludi", [&] { run_faludi(*a); });
    });
}

}  // namespace lacuna::cli
