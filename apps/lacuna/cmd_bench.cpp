// `lacuna bench ...`: reproducible benchmarks (docs/benchmarks.md).
#include "cli_common.h"

namespace lacuna::cli {

void register_bench(CLI::App& app) {
    auto* cmd = app.add_subcommand("bench", "Benchmarks (docs/benchmarks.md)");
    cmd->require_subcommand(1);
}

}  // namespace lacuna::cli
