// Build and TF-change time of every skipping structure on the generated tree volume
// (docs/benchmarks.md). `accel_build --benchmark_filter=Build/bitfield` etc.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "lacuna/accel.h"
#include "lacuna/synthetic.h"
#include "lacuna/transfer_function.h"

namespace {

using namespace lacuna;

// One tree volume per edge, generated on first use and kept for the whole run.
const Volume& tree(int n) {
    static std::map<int, std::unique_ptr<Volume>> cache;
    auto& v = cache[n];
    if (!v) {
        SyntheticOptions so;
        so.dims = {n, n, n};
        v = std::make_unique<Volume>(generate(SyntheticKind::Tree, so));
    }
    return *v;
}

// Build (TF-independent part plus the first TF): state.range(0) = kind index, range(1) = edge.
void Build(benchmark::State& state) {
    const AccelKind kind = all_accel_kinds()[size_t(state.range(0))];
    const Volume& v = tree(int(state.range(1)));
    const TransferLut lut = discretise(preset("mr-default"), v.vis_range());
    for (auto _ : state) {
        auto accel = make_accel(kind, v);
        accel->set_transfer_function(lut);
        benchmark::DoNotOptimize(accel.get());
    }
    state.SetLabel(to_string(kind));
}

// A TF change on a built structure.
void TfChange(benchmark::State& state) {
    const AccelKind kind = all_accel_kinds()[size_t(state.range(0))];
    const Volume& v = tree(int(state.range(1)));
    const TransferLut a = discretise(preset("mr-default"), v.vis_range());
    const TransferLut b = discretise(preset("mr-gap"), v.vis_range());
    auto accel = make_accel(kind, v);
    bool flip = false;
    for (auto _ : state) {
        accel->set_transfer_function(flip ? a : b);
        flip = !flip;
    }
    state.SetLabel(to_string(kind));
}

void kinds_and_sizes(benchmark::internal::Benchmark* b) {
    for (int k = 1; k < int(all_accel_kinds().size()); ++k)
        for (int n : {256, 512}) b->Args({k, n});
}

BENCHMARK(Build)->Apply(kinds_and_sizes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(TfChange)->Apply(kinds_and_sizes)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
