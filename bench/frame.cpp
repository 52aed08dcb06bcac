// One frame per skipping structure on the generated tree volume (docs/benchmarks.md); the
// counters report samples per ray. `frame --benchmark_filter=Frame`.
#include <benchmark/benchmark.h>

#include <memory>

#include "lacuna/accel.h"
#include "lacuna/renderer.h"
#include "lacuna/synthetic.h"
#include "lacuna/transfer_function.h"

namespace {

using namespace lacuna;

const Volume& tree256() {
    static const Volume v = [] {
        SyntheticOptions so;
        so.dims = {256, 256, 256};
        return generate(SyntheticKind::Tree, so);
    }();
    return v;
}

// state.range(0) = kind index, range(1) = 1 for early ray termination.
void Frame(benchmark::State& state) {
    const AccelKind kind = all_accel_kinds()[size_t(state.range(0))];
    const Volume& v = tree256();
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    auto accel = make_accel(kind, v);
    accel->set_transfer_function(lut);
    RayMarcher m(v);
    m.set_transfer_function(lut);
    m.set_accel(accel.get());
    OrbitParams p;
    p.azimuth_deg = 210;  // azimuth 30 before issue 14's anatomical azimuth: the same view
    const Camera cam = Camera::orbit(m.bounds(), p, 512, 512);
    RenderOptions ro;
    ro.ert = state.range(1) ? 0.99f : 2.f;
    RenderStats last;
    for (auto _ : state) last = m.render(cam, ro).stats;
    state.counters["samples_per_ray"] = last.samples_per_ray();
    state.counters["Msamples_per_s"] = last.msamples_per_second();
    state.SetLabel(to_string(kind) + (state.range(1) ? " +ERT" : ""));
}

BENCHMARK(Frame)
    ->ArgsProduct({benchmark::CreateDenseRange(0, int(all_accel_kinds().size()) - 1, 1), {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
