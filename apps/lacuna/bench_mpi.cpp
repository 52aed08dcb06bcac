// `lacuna bench mpi`: distributed rendering measured (docs/distributed.md, "Measurements").
//
// A driver, run as one process: it writes the volumes, then starts `mpirun --oversubscribe -np N
// lacuna render ... --rank-times` for each rank count and reads every rank's row of the report
// (load, build, render, composite and CPU times, samples, voxels, bytes sent), for
//   - strong scaling: one volume, N = 1, 2, 4 (--ranks);
//   - weak scaling: the volume grows with N (N times the voxels of --weak³, doubled along x,
//     then y, then z), the image fixed;
// and `mpirun -np N lacuna bench mpi --worker`, which composites synthetic full-image partials
// with each algorithm (after a barrier, rank 0's time, median of --repeat) to fit the cost
// model of src/dist/composite_model.h, checks its message, byte and pixel counts against what
// composite.cpp counted, and evaluates it at 64-1024 ranks and an 8K image.
//
// On this 2-core machine the ranks are oversubscribed, so wall times do not fall with N; the
// CPU time of each rank's render (getrusage, all its threads) is what scales, and is reported.
// Nothing here gates a test: timings are reported, never asserted.
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "bench_cli.h"
#include "cli_common.h"
#include "dist/comm.h"
#include "dist/composite.h"
#include "dist/composite_model.h"
#include "dist/decomposition.h"
#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/synthetic.h"

namespace lacuna::cli {

namespace {

namespace fs = std::filesystem;

struct MpiBenchArgs {
    std::string ranks = "1,2,4";
    std::string composite_ranks = "2,3,4";
    std::string composite_sizes = "256,512,1024";
    int size = 512;    // image edge of the scaling frames
    int strong = 256;  // edge of the strong-scaling volume
    int weak = 160;    // edge of the weak-scaling volume per rank
    int repeat = 5;    // compositing repetitions (median)
    std::string tf = "ct-bone";
    std::string mpirun = "mpirun";
    std::string out_dir = "out/bench/mpi";
    bool quick = false;
    bool worker = false;
    bool cold_pages = false;  // the worker leaves glibc's allocator as it is
};

// ---- the worker: compositing under mpirun --------------------------------------------------

// A full-image partial: every pixel non-empty (the model's upper bound), different per rank.
dist::Partial synthetic_partial(int w, int h, int rank) {
    dist::Partial p{w, h, std::vector<float>(size_t(w) * size_t(h) * 4)};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float a = 0.2f + 0.6f * float((x * 7 + y * 13 + rank * 29) % 97) / 97.f;
            float* c = p.at(x, y);
            c[0] = a * 0.9f, c[1] = a * 0.5f, c[2] = a * 0.2f, c[3] = a;
        }
    return p;
}

void run_worker(const MpiBenchArgs& a) {
    // Freed buffers stay in the heap, so a repetition reuses pages the last one touched: on this
    // VM a first touch costs tens of microseconds per 4 KiB page (paravirtualised faults), which
    // would swamp a 1024² image's compositing (docs/distributed.md, "Compositing cost model").
    if (!a.cold_pages) {
        mallopt(M_MMAP_THRESHOLD, 1 << 30);
        mallopt(M_TRIM_THRESHOLD, 1 << 30);
    }
    dist::Comm& comm = dist::Comm::world();
    const int n = comm.size();
    const dist::Decomposition d = dist::decompose_voxels({97, 89, 83}, n);
    const Vec3f eye{-150.f, 40.f, 60.f}, dir{1.f, 0.f, 0.f};
    // The link between ranks 0 and 1 by ping-pong: half the round trip, median of --repeat.
    for (size_t bytes : {size_t(16), size_t(1) << 16, size_t(1) << 20, size_t(1) << 24}) {
        std::vector<uint8_t> buf(bytes, 1);
        std::vector<double> times;
        for (int r = 0; r < std::max(3, a.repeat); ++r) {
            comm.barrier();
            const auto t0 = std::chrono::steady_clock::now();
            if (comm.rank() == 0 && n > 1) {
                comm.send(1, 900, buf.data(), bytes);
                comm.recv(1, 901, buf.data(), bytes);
            } else if (comm.rank() == 1) {
                comm.recv(0, 900, buf.data(), bytes);
                comm.send(0, 901, buf.data(), bytes);
            }
            times.push_back(
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 2);
        }
        std::sort(times.begin(), times.end());
        if (comm.rank() == 0 && n > 1)
            std::printf("pingpong %zu %.9f\n", bytes, times[times.size() / 2]);
    }
    for (const std::string& s : split_list(a.composite_sizes)) {
        const int edge = parse_count(s, "--composite-sizes", a.composite_sizes);
        const dist::Partial base = synthetic_partial(edge, edge, comm.rank());
        for (dist::Composite alg :
             {dist::Composite::Direct, dist::Composite::BinarySwap, dist::Composite::RadixK}) {
            std::vector<double> times;
            dist::CompositeStats last;
            for (int r = 0; r < std::max(1, a.repeat); ++r) {
                dist::Partial mine = base;
                dist::CompositeStats st;
                comm.barrier();
                const auto t0 = std::chrono::steady_clock::now();
                if (alg == dist::Composite::Direct)
                    dist::composite_direct(comm, mine, dist::visibility_order(d, eye, dir, false),
                                           st);
                else if (alg == dist::Composite::BinarySwap)
                    dist::composite_binary_swap(comm, std::move(mine), d, eye, dir, false, st);
                else
                    dist::composite_radix_k(comm, std::move(mine), d, eye, dir, false, 4, st);
                times.push_back(
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
                last = st;
            }
            std::sort(times.begin(), times.end());
            if (comm.rank() == 0)
                std::printf("composite %s %d %d %.9f %llu %llu %llu\n",
                            dist::to_string(alg).c_str(), n, edge, times[times.size() / 2],
                            (unsigned long long)last.messages_received,
                            (unsigned long long)last.bytes_received,
                            (unsigned long long)last.pixels_composited);
        }
    }
    std::fflush(stdout);
}

// ---- the driver ---------------------------------------------------------------------------

std::string self_exe() {
    std::error_code ec;
    const fs::path p = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error("bench mpi", "executable", "cannot find this program (/proc/self/exe)");
    return p.string();
}

std::string mpirun_prefix(const MpiBenchArgs& a, int ranks) {
    return a.mpirun + (::geteuid() == 0 ? " --allow-run-as-root" : "") + " --oversubscribe -np " +
           std::to_string(ranks) + " ";
}

// Runs `cmd`, returns its stdout; throws with its output when it fails.
std::string run(const std::string& cmd) {
    std::string out;
    const std::string full = cmd + " 2>&1";
    FILE* f = ::popen(full.c_str(), "r");
    if (!f) throw Error("bench mpi", "command", "cannot run: " + cmd);
    char buf[4096];
    size_t got;
    while ((got = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, got);
    const int status = ::pclose(f);
    if (status != 0)
        throw Error("bench mpi", "command", "failed: " + cmd + "\n" + out.substr(0, 2000));
    return out;
}

// One rank's row of `--rank-times`.
struct RankRow {
    int rank = 0;
    double load = 0, build = 0, render = 0, composite = 0, cpu = 0;
    unsigned long long samples = 0;
    double voxels = 0, read = 0, sent_kib = 0, peak_mib = 0;
};
struct Frame {
    int ranks = 0;
    std::string volume;
    double frame_ms = 0, wall_s = 0;
    std::vector<RankRow> rows;
};

Frame parse_frame(const std::string& out, int ranks, const std::string& volume, double wall) {
    Frame f;
    f.ranks = ranks, f.volume = volume, f.wall_s = wall;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("frame ", 0) == 0) std::sscanf(line.c_str(), "frame %lf", &f.frame_ms);
        RankRow r;
        if (std::sscanf(line.c_str(), "%d %lf %lf %lf %lf %lf %llu %lf %lf %lf %lf", &r.rank,
                        &r.load, &r.build, &r.render, &r.composite, &r.cpu, &r.samples, &r.voxels,
                        &r.read, &r.sent_kib, &r.peak_mib) == 11)
            f.rows.push_back(r);
    }
    if (int(f.rows.size()) != ranks)
        throw Error("bench mpi", "report",
                    "expected " + std::to_string(ranks) + " rank rows, got:\n" + out);
    return f;
}

Frame render_frame(const MpiBenchArgs& a, const std::string& exe, int ranks, const fs::path& vol,
                   const fs::path& png) {
    const std::string cmd = mpirun_prefix(a, ranks) + exe + " render " + vol.string() + " --tf " +
                            a.tf + " --size " + std::to_string(a.size) +
                            " --rank-times --composite direct --out " + png.string();
    log_line("  " + cmd);
    const auto t0 = std::chrono::steady_clock::now();
    const std::string out = run(cmd);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return parse_frame(out, ranks, vol.filename().string(), wall);
}

fs::path write_tree(const fs::path& dir, Vec3i dims) {
    const fs::path p = dir / ("tree_" + std::to_string(dims.x) + "x" + std::to_string(dims.y) +
                              "x" + std::to_string(dims.z) + "_uint8.raw");
    if (fs::exists(p)) return p;
    SyntheticOptions o;
    o.dims = dims;
    write_volume(p.string(), generate(SyntheticKind::Tree, o));
    return p;
}

// The weak-scaling grid of N ranks: N times base³ voxels, doubling x, y, z in turn (N a power
// of two), else N·base along x.
Vec3i weak_dims(int base, int n) {
    Vec3i d{base, base, base};
    if ((n & (n - 1)) != 0) return {base * n, base, base};
    for (int a = 0, m = n; m > 1; m /= 2, a = (a + 1) % 3) d[a] *= 2;
    return d;
}

std::string fmt(const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

// The scaling table: a line per rank count with the slowest rank, the CPU times and the balance.
void scaling_table(std::ostringstream& md, const std::vector<Frame>& frames, bool weak) {
    md << "| ranks | volume | frame ms | wall s (mpirun) | load ms (max) | build ms (max) | render "
          "ms (max) | composite ms (max) | CPU ms per rank | CPU ms total | samples max/mean | "
          "voxels % per rank | read % per rank | sent KiB (sum) | "
       << (weak ? "CPU efficiency" : "CPU speedup") << " |\n";
    md << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    double cpu1 = 0;
    for (const Frame& f : frames) {
        double load = 0, build = 0, render = 0, comp = 0, cpu_max = 0, cpu_sum = 0, sent = 0;
        double smax = 0, ssum = 0;
        std::string cpus, vox, read;
        for (const RankRow& r : f.rows) {
            load = std::max(load, r.load), build = std::max(build, r.build);
            render = std::max(render, r.render), comp = std::max(comp, r.composite);
            cpu_max = std::max(cpu_max, r.cpu), cpu_sum += r.cpu, sent += r.sent_kib;
            smax = std::max(smax, double(r.samples)), ssum += double(r.samples);
            cpus += (cpus.empty() ? "" : ", ") + fmt("%.0f", r.cpu);
            vox += (vox.empty() ? "" : ", ") + fmt("%.1f", r.voxels);
            read += (read.empty() ? "" : ", ") + fmt("%.1f", r.read);
        }
        if (f.ranks == frames.front().ranks) cpu1 = cpu_max * (weak ? 1 : f.ranks);
        const double balance = ssum > 0 ? smax / (ssum / double(f.rows.size())) : 1;
        // Strong: the one-rank CPU time over the slowest rank's (one core per rank); weak: the
        // one-rank CPU time over the slowest rank's (1 is perfect).
        const double score = cpu_max > 0 ? cpu1 / cpu_max : 0;
        md << "| " << f.ranks << " | " << f.volume << " | " << fmt("%.1f", f.frame_ms) << " | "
           << fmt("%.1f", f.wall_s) << " | " << fmt("%.0f", load) << " | " << fmt("%.0f", build)
           << " | " << fmt("%.1f", render) << " | " << fmt("%.1f", comp) << " | " << cpus << " | "
           << fmt("%.0f", cpu_sum) << " | " << fmt("%.2f", balance) << " | " << vox << " | " << read
           << " | " << fmt("%.0f", sent) << " | " << fmt(weak ? "%.2f" : "%.2f", score) << " |\n";
    }
}

void run_driver(const MpiBenchArgs& a) {
    const fs::path dir = create_out_dir(a.out_dir);
    const std::string exe = self_exe();
    std::ostringstream md;
    md << "# lacuna bench mpi\n\n`" << command_line("lacuna bench mpi") << "`\n\n";
    std::vector<int> ranks;
    for (const std::string& s : split_list(a.ranks))
        ranks.push_back(parse_count(s, "--ranks", a.ranks));
    if (ranks.empty()) throw Error("--ranks", "list", "expected at least one rank count");
    std::sort(ranks.begin(), ranks.end());

    // 1. Strong scaling: one volume.
    log_line("strong scaling: tree " + std::to_string(a.strong) + "^3, " + std::to_string(a.size) +
             "^2 image");
    const fs::path strong = write_tree(dir, {a.strong, a.strong, a.strong});
    std::vector<Frame> sf;
    for (int n : ranks)
        sf.push_back(
            render_frame(a, exe, n, strong, dir / ("strong_" + std::to_string(n) + ".png")));
    md << "## Strong scaling\n\n`--tf " << a.tf << " --size " << a.size
       << " --composite direct`, the raw file read by offset. CPU speedup: the one-rank CPU time "
          "over the slowest rank's (the frame's time with a core per rank).\n\n";
    scaling_table(md, sf, false);

    // 2. Weak scaling: N times the voxels.
    log_line("weak scaling: tree " + std::to_string(a.weak) + "^3 per rank");
    std::vector<Frame> wf;
    for (int n : ranks) {
        const fs::path v = write_tree(dir, weak_dims(a.weak, n));
        wf.push_back(render_frame(a, exe, n, v, dir / ("weak_" + std::to_string(n) + ".png")));
    }
    md << "\n## Weak scaling\n\nThe volume holds N times " << a.weak
       << "³ voxels (doubled along x, y, z in turn). CPU efficiency: the one-rank CPU time over "
          "the slowest rank's (1 is perfect; the image is fixed, so each rank's share of the "
          "rays shrinks while its ray length grows).\n\n";
    scaling_table(md, wf, true);

    // 3. Compositing: measured, counted, fitted, extrapolated.
    log_line("compositing: sizes " + a.composite_sizes + ", ranks " + a.composite_ranks);
    std::vector<dist::CompositeSample> samples;
    struct Row {
        std::string alg;
        int n, edge;
        double seconds;
        dist::CompositeCounts counted, model;
    };
    std::vector<Row> rows;
    std::vector<std::pair<double, double>> pingpong;  // from the first run
    size_t mismatches = 0;
    for (const std::string& s : split_list(a.composite_ranks)) {
        const int n = parse_count(s, "--composite-ranks", a.composite_ranks);
        const std::string cmd = mpirun_prefix(a, n) + exe +
                                " bench mpi --worker --composite-sizes " + a.composite_sizes +
                                " --repeat " + std::to_string(a.repeat);
        log_line("  " + cmd);
        std::istringstream in(run(cmd));
        std::string line;
        const bool first_link = pingpong.empty();
        while (std::getline(in, line)) {
            size_t bytes;
            double sec;
            if (std::sscanf(line.c_str(), "pingpong %zu %lf", &bytes, &sec) == 2) {
                if (first_link) pingpong.push_back({double(bytes), sec});
                continue;
            }
            char alg[32];
            int rn, edge;
            unsigned long long m, b, p;
            if (std::sscanf(line.c_str(), "composite %31s %d %d %lf %llu %llu %llu", alg, &rn,
                            &edge, &sec, &m, &b, &p) != 7)
                continue;
            Row r{alg, rn, edge, sec, {double(m), double(b), double(p)}, {}};
            const dist::Composite c = r.alg == "direct"        ? dist::Composite::Direct
                                      : r.alg == "binary-swap" ? dist::Composite::BinarySwap
                                                               : dist::Composite::RadixK;
            r.model = dist::composite_counts(c, rn, edge, edge, 4);
            if (r.model.messages != r.counted.messages || r.model.bytes != r.counted.bytes ||
                r.model.pixels != r.counted.pixels)
                ++mismatches;
            samples.push_back({r.counted, sec});
            rows.push_back(r);
        }
    }
    // The link by ping-pong, then the per-pixel cost fitted to the compositing runs.
    dist::CompositeModel model;
    dist::fit_link(pingpong, model.latency, model.bandwidth);
    model.pixel_cost = dist::fit_pixel_cost(samples, model);
    const dist::CompositeModel free_fit = dist::fit_composite_model(samples);
    md << "\n## Compositing\n\nSynthetic partials covering the whole image (every pixel "
          "non-empty: the upper bound), composited after a barrier; rank 0's time, median of "
       << a.repeat
       << ". Counts of rank 0 (messages, bytes, pixels through over) as composite.cpp "
          "counted them; "
       << (mismatches == 0 ? "every count equals the model's (composite_counts)"
                           : std::to_string(mismatches) + " rows differ from the model's counts")
       << ".\n\nThe model T = α·messages + bytes/β + γ·pixels: α and β from a ping-pong "
          "between ranks 0 and 1 (";
    for (const auto& [b, t] : pingpong)
        md << fmt("%.0f B: ", b) << fmt("%.1f us", t * 1e6)
           << (&b == &pingpong.back().first ? "" : ", ");
    md << "), γ fitted to the rows below: " << dist::to_string(model)
       << ". (All three fitted to the rows: " << dist::to_string(free_fit) << ".)\n\n";
    md << "| algorithm | ranks | image | measured ms | model ms | error | messages | MiB | "
          "Mpixels |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
        const double m = model.seconds(r.counted);
        md << "| " << r.alg << " | " << r.n << " | " << r.edge << "² | "
           << fmt("%.2f", r.seconds * 1e3) << " | " << fmt("%.2f", m * 1e3) << " | "
           << fmt("%+.0f%%", 100.0 * (m - r.seconds) / r.seconds) << " | "
           << fmt("%.0f", r.counted.messages) << " | " << fmt("%.2f", r.counted.bytes / 1048576.0)
           << " | " << fmt("%.2f", r.counted.pixels * 1e-6) << " |\n";
    }
    // 4. The model at scale: an 8K frame (7680 x 4320).
    const dist::CompositeModel& fit = model;
    dist::CompositeModel net = model;
    net.latency = 2e-6, net.bandwidth = 10e9;  // a nominal cluster network
    md << "\n## The model at 64-1024 ranks, 8K image (7680x4320, full-image partials)\n\n"
          "This machine: the model above (shared memory, oversubscribed). Network: latency "
          "2 us and 10 GB/s (a 100 Gb/s InfiniBand link) with this machine's per-pixel cost.\n\n"
          "| ranks | direct s (this machine / network) | binary-swap s | radix-k s | rank 0 "
          "receives (direct / binary-swap / radix-k) |\n|---|---|---|---|---|\n";
    for (int n : {64, 128, 256, 512, 1024}) {
        md << "| " << n;
        std::string recv;
        for (dist::Composite c :
             {dist::Composite::Direct, dist::Composite::BinarySwap, dist::Composite::RadixK}) {
            const dist::CompositeCounts k = dist::composite_counts(c, n, 7680, 4320, 4);
            md << " | " << fmt("%.3f", fit.seconds(k)) << " / " << fmt("%.3f", net.seconds(k));
            recv += (recv.empty() ? "" : " / ") + fmt("%.2f GiB", k.bytes / 1073741824.0);
        }
        md << " | " << recv << " |\n";
    }
    const fs::path mdp = dir / "mpi.md";
    std::ofstream(mdp) << md.str();
    std::fputs(md.str().c_str(), stdout);
    log_line("wrote " + mdp.string());
}

}  // namespace

void register_bench_mpi(CLI::App& bench) {
    auto a = std::make_shared<MpiBenchArgs>();
    auto* c = bench.add_subcommand(
        "mpi",
        "Distributed rendering: per-rank times, strong and weak scaling, compositing model "
        "(docs/distributed.md)");
    c->add_option("--ranks", a->ranks, "Rank counts of the scaling runs")->capture_default_str();
    c->add_option("--composite-ranks", a->composite_ranks, "Rank counts of the compositing runs")
        ->capture_default_str();
    c->add_option("--composite-sizes", a->composite_sizes, "Image edges of the compositing runs")
        ->capture_default_str();
    c->add_option("--size", a->size, "Image edge of the scaling frames")->capture_default_str();
    c->add_option("--strong", a->strong, "Edge of the strong-scaling volume")
        ->capture_default_str();
    c->add_option("--weak", a->weak, "Edge of the weak-scaling volume per rank")
        ->capture_default_str();
    c->add_option("--repeat", a->repeat, "Compositing repetitions (median)")->capture_default_str();
    c->add_option("--tf", a->tf, "Transfer function of the scaling frames")->capture_default_str();
    c->add_option("--mpirun", a->mpirun, "The MPI launcher")->capture_default_str();
    c->add_option("--out-dir", a->out_dir, "Folder for the volumes, images and mpi.md")
        ->capture_default_str();
    c->add_flag("--quick", a->quick, "Smoke run: tiny volumes and images");
    c->add_flag("--worker", a->worker, "(internal) the compositing measurement, under mpirun");
    c->add_flag("--cold-pages", a->cold_pages,
                "(with --worker) keep glibc's allocator defaults: buffers on fresh pages");
    c->callback([a, c] {
        if (a->worker) return run_worker(*a);
        if (a->quick) {
            if (!c->count("--ranks")) a->ranks = "1,2";
            if (!c->count("--composite-ranks")) a->composite_ranks = "2,3";
            if (!c->count("--composite-sizes")) a->composite_sizes = "32,64";
            if (!c->count("--size")) a->size = 48;
            if (!c->count("--strong")) a->strong = 40;
            if (!c->count("--weak")) a->weak = 24;
            if (!c->count("--repeat")) a->repeat = 2;
        }
        if (a->size < 1 || a->size > 16384)
            throw Error("--size", "image size", "expected 1..16384");
        if (a->strong < 2 || a->weak < 2) throw Error("--strong", "volume", "expected edges >= 2");
        with_summary("bench mpi", [&] { run_driver(*a); });
    });
}

}  // namespace lacuna::cli
