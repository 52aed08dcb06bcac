// `mpirun -np N lacuna render ...`: the frame rendered by every rank (src/dist/,
// docs/distributed.md). Kept out of cmd_render.cpp so the single-process path stays as it was.
#pragma once
#include <string>

#include "cli_common.h"
#include "lacuna/frame_spec.h"
#include "lacuna/transfer_function.h"

namespace lacuna::cli {

struct MpiCliArgs {
    std::string balance = "voxels";    // --balance voxels|visible
    std::string composite = "direct";  // --composite direct|binary-swap
    bool rank_times = false;           // --rank-times: rank 0 prints every rank's times
};
void add_mpi_options(CLI::App& cmd, MpiCliArgs& a);
// True when this process runs under an MPI launcher in a build with MPI: `render` then renders
// distributed (the flags are those of one process).
bool mpi_render_active();
// Throws lacuna::Error for a --balance/--composite name not in the lists.
void check_mpi_options(const MpiCliArgs& a);

struct MpiRenderJob {
    VolumeArgs volume;
    TransferFunction tf;
    std::string accel, out;  // accel: the --accel name, for the report
    std::string heatmap;     // --heatmap: every rank's samples per pixel, summed
    int threads = 0;
    FrameSpec spec;
    MpiCliArgs mpi;
};
// Rank 0 writes the PNG and the report; the others write nothing.
void render_mpi(const MpiRenderJob& job);

}  // namespace lacuna::cli
