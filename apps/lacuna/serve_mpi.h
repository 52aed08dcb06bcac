// `mpirun -np N lacuna serve VOLUME`: rank 0 serves the page, every rank renders its brick of
// each frame (docs/distributed.md, "The viewer"). Kept out of cmd_serve.cpp like render_mpi.h.
#pragma once
#include <memory>

#include "dist/rank_loop.h"
#include "render_mpi.h"
#include "serve/frame_renderer.h"

namespace lacuna::cli {

// Rank 0's frames from every rank (serve::FrameSource over dist::RankDriver): the frame spec the
// page asked for, refused as `mpirun lacuna render` refuses it (check_distributable), early
// termination off.
class DistributedFrames : public serve::FrameSource {
  public:
    explicit DistributedFrames(dist::RankDriver& driver) : m_driver(driver) {}
    FrameResult render(const TransferFunction& tf, const FrameSpec& spec) override;
    void refine() override { m_driver.refine(); }

  private:
    dist::RankDriver& m_driver;
    bool m_built = false;
};

}  // namespace lacuna::cli
