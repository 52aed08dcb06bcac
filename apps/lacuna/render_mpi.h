// `mpirun -np N lacuna render ...`: the frame rendered by every rank (src/dist/,
// docs/distributed.md). Kept out of cmd_render.cpp so the single-process path stays as it was.
#pragma once
#include <string>
#include <vector>

#include "cli_common.h"
#include "dist/distributed_frame.h"
#include "lacuna/frame_spec.h"
#include "lacuna/transfer_function.h"

namespace lacuna::cli {

struct MpiCliArgs {
    std::string balance = "voxels";    // --balance voxels|visible
    std::string composite = "direct";  // --composite direct|binary-swap
    bool rank_times = false;           // --rank-times: rank 0 prints every rank's times
};
// rank_times: also --rank-times (render; the viewer has no report to add it to).
void add_mpi_options(CLI::App& cmd, MpiCliArgs& a, bool rank_times = true);
// True when this process runs under an MPI launcher in a build with MPI: `render` then renders
// distributed (the flags are those of one process).
bool mpi_render_active();
// Throws lacuna::Error for a --balance/--composite name not in the lists.
void check_mpi_options(const MpiCliArgs& a);

// The flags' options (check_mpi_options's errors).
dist::DistOptions dist_options(const MpiCliArgs& a);
// Throws lacuna::Error for a frame distributed rendering cannot take yet (every rank alike).
void check_distributable(const FrameSpec& spec);
// Where the ranks' voxels come from: by offset when the file allows it, else the whole file
// through load_volume (a header's errors are thrown here, on every rank alike).
dist::VolumeSource volume_source(const VolumeArgs& v);

struct MpiRenderJob {
    VolumeArgs volume;
    TransferFunction tf;
    std::string accel, out;  // accel: the --accel name, for the report
    std::string heatmap;     // --heatmap: every rank's samples per pixel, summed
    int threads = 0;
    FrameSpec spec;
    MpiCliArgs mpi;
    // --orbit N: frame i at azimuths[i], written to outs[i] (empty: the one frame of `spec` to
    // `out`). The bricks and their structures are made once for all frames.
    std::vector<float> azimuths;
    std::vector<std::string> outs;
    int repeat = 1;  // --repeat: the report's times are the median of the frames after the first
};
// Rank 0 writes the PNGs and the report; the others write nothing.
void render_mpi(const MpiRenderJob& job);

}  // namespace lacuna::cli
