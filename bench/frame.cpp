// One frame per skipping structure on the generated tree volume (docs/benchmarks.md); the
// counters report samples per ray. Frames render through lacuna::Session. `frame
// --benchmark_filter=Frame`.
#include <benchmark/benchmark.h>

#include <memory>

#include "lacuna/accel.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
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

// state.range(0) = kind index, range(1) = 1 for early ray termination. The frame goes through a
// Session, as every front end's (the structure is built and TF-synced by the first render).
void Frame(benchmark::State& state) {
    const AccelKind kind = all_accel_kinds()[size_t(state.range(0))];
    Session session(tree256());  // shares the voxels
    session.set_transfer_function(preset("mr-default"));
    FrameSpec f;
    f.structure = structure_of(kind);
    f.camera.orbit.azimuth_deg =
        210;  // azimuth 30 before issue 14's anatomical azimuth: the same view
    f.width = f.height = 512;
    if (!state.range(1)) f.sampling.early_termination.reset();
    session.render(f);  // builds the structure
    RenderStats last;
    for (auto _ : state) last = session.render(f).stats;
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
