// One 512² slice view (lacuna/mpr.h) of ch2better through its centre, per plane, trilinear and
// nearest, on all threads and on one (docs/benchmarks.md "Slice views"; issue 18's target:
// <= 30 ms per 512² slice). The pixel is chosen so the slice's shorter side spans 512 pixels and
// the longer side is cropped to 512: every pixel is inside the head's volume (the worst case; a
// pixel outside is one comparison). A round = sample_slice + window_level (the server's work
// before JPEG). Reported: the median of the repetitions, real time, the main thread's CPU time
// and cpu_ms, the whole process's CPU time per slice (all threads).
//   mpr --benchmark_repetitions=15 --benchmark_report_aggregates_only=true
#include "lacuna/mpr.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/parallel.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"

namespace {

using namespace lacuna;

const char* kPath = "/usr/share/mricron/templates/ch2better.nii.gz";

const Volume& ch2better() {
    static const Volume v = [] {
        Volume r = read_volume(kPath);
        r.compute_range();
        return r;
    }();
    return v;
}

SliceGeometry geometry_512(const Volume& v, SlicePlane plane) {
    const Vec3d centre = Vec3d(world_bounds(v).center());
    const SliceGeometry full = slice_geometry(v, plane, centre);
    const double shorter = double(std::min(full.width, full.height) - 1) * full.pixel_mm;
    SliceOptions o;
    o.pixel_mm = shorter / 511;
    SliceGeometry g = slice_geometry(v, plane, centre, o);
    g.width = g.height = 512;  // crop the longer side
    return g;
}

// range(0): plane, range(1): 1 = nearest, range(2): threads (0 = all)
void Slice512(benchmark::State& state) {
    const Volume& v = ch2better();
    const SlicePlane plane = SlicePlane(state.range(0));
    const Interpolation interp = state.range(1) ? Interpolation::Nearest : Interpolation::Trilinear;
    const int threads = int(state.range(2));
    const SliceGeometry g = geometry_512(v, plane);
    size_t inside = 0;
    double cpu = 0;
    for (auto _ : state) {
        const double c0 = process_cpu_seconds();
        const Slice s = sample_slice(v, g, interp, threads);
        const Image img = window_level(s, 100, 50);
        cpu += process_cpu_seconds() - c0;
        benchmark::DoNotOptimize(img.rgba.data());
        inside =
            size_t(std::count_if(s.values.begin(), s.values.end(), [](float x) { return x == x; }));
    }
    state.counters["cpu_ms"] = benchmark::Counter(cpu * 1e3 / double(state.iterations()));
    state.counters["inside"] = double(inside) / (512.0 * 512.0);
    state.SetLabel(to_string(plane) + " " + to_string(interp) +
                   (threads ? " threads=" + std::to_string(threads) : " all threads"));
}

BENCHMARK(Slice512)
    ->ArgsProduct({{0, 1, 2}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
    if (std::FILE* f = std::fopen(kPath, "rb"))
        std::fclose(f);
    else {
        std::fprintf(stderr, "mpr: %s: not found (Debian's mricron-data)\n", kPath);
        return 1;
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
