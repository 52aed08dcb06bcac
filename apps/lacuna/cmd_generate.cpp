// `lacuna generate KIND --dims AxBxC --out FILE`: synthetic volumes for tests and benchmarks.
#include <cstdio>

#include "cli_common.h"
#include "lacuna/error.h"
#include "lacuna/synthetic.h"

namespace lacuna::cli {

namespace {

struct GenerateArgs {
    std::string kind, dims = "64x64x64", type = "uint8", out;
    uint32_t seed = 1;
};

void run(const GenerateArgs& a) {
    const SyntheticKind kind = parse_synthetic_kind(a.kind);
    SyntheticOptions so;
    so.dims = parse_dims(a.dims, "--dims");
    so.type = parse_voxel_type(a.type, "--type");
    so.seed = a.seed;
    if (a.out.empty()) throw Error("generate", "--out", "expected an output volume file");
    Progress summary("generate", 0, "");
    Progress progress("generating " + a.kind);
    const Volume v = generate(kind, so);
    progress.done();
    write_volume(a.out, v);
    std::printf("wrote %s: %s\n", a.out.c_str(), to_string(v).c_str());
    std::fflush(stdout);
    summary.done();
}

}  // namespace

void register_generate(CLI::App& app) {
    auto a = std::make_shared<GenerateArgs>();
    auto* cmd = app.add_subcommand("generate", "Write a synthetic volume");
    std::string kinds;
    for (const auto& k : synthetic_kind_names()) kinds += (kinds.empty() ? "" : ", ") + k;
    cmd->add_option("kind", a->kind, "One of: " + kinds)->required();
    cmd->add_option("--dims", a->dims, "Dimensions AxBxC")->capture_default_str();
    cmd->add_option("--type", a->type, "uint8, int16, uint16 or float32")->capture_default_str();
    cmd->add_option("--seed", a->seed, "Random seed")->capture_default_str();
    cmd->add_option("--out,-o", a->out, "Output file (.nrrd .nhdr .nii .nii.gz .mha .mhd)")
        ->required();
    cmd->callback([a] { run(*a); });
}

}  // namespace lacuna::cli
