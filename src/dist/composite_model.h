// A cost model of sort-last compositing (docs/distributed.md, "Compositing cost model"), to say
// what the three algorithms of composite.h cost at rank counts and image sizes this machine
// cannot run.
//
// The model. Rank 0 is on every algorithm's critical path (it takes part in every round and
// gathers the image at the end), so a frame's compositing time is rank 0's: each message it
// receives costs a latency α, each byte 1/β, each pixel it puts through over γ,
//     T = α · messages + bytes / β + γ · pixels,
// the latency-bandwidth ("postal") model of Peterka et al. 2009 (radix-k), with the compositing
// arithmetic as a third term. The counts come from the algorithms' own row splits
// (composite_counts walks rank 0's rounds exactly as composite.cpp does), for partials that
// cover the whole image (every pixel non-empty: the upper bound; a brick's real footprint only
// shrinks what is sent). Per algorithm, for N ranks (P = largest power of two <= N, E = N - P
// folded first) and an image of A pixels of 16 bytes (float RGBA):
//     direct       2(N-1) messages,  16·A·(N-1) bytes,  A·N pixels: rank 0 takes everything;
//     binary swap  2·log2 P + 2(P-1) messages, about 16·A·(2 - 2/P) bytes and 2·A pixels
//                  (log2 P halvings of A, then the gather of P strips);
//     radix-k      2(k-1) messages per round of k, log_k P rounds, then the gather; bytes about
//                  binary swap's (a round receives (k-1)/k of the current rows), pixels more
//                  (a round composites all k pieces of its part, its own included).
// α, β, γ are fitted by least squares to measured compositing times (`lacuna bench mpi`),
// which also checks the counts against what composite.cpp counted (CompositeStats).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "dist/composite.h"

namespace lacuna::dist {

// What rank 0 receives and composites in one frame.
struct CompositeCounts {
    double messages = 0, bytes = 0, pixels = 0;
};
// For partials covering the whole width x height image, N = `ranks`, radix k = `k`.
CompositeCounts composite_counts(Composite c, int ranks, int width, int height, int k = 4);

struct CompositeModel {
    double latency = 0;     // α, seconds per message
    double bandwidth = 0;   // β, bytes per second
    double pixel_cost = 0;  // γ, seconds per pixel composited
    double seconds(const CompositeCounts& c) const {
        return latency * c.messages + (bandwidth > 0 ? c.bytes / bandwidth : 0) +
               pixel_cost * c.pixels;
    }
};
std::string to_string(const CompositeModel& m);

struct CompositeSample {
    CompositeCounts counts;
    double seconds = 0;  // measured
};
// α and β of one link from ping-pong times (bytes, one-way seconds): t = α + bytes / β by
// least squares on the relative error. Throws lacuna::Error for fewer than 2 sizes.
void fit_link(const std::vector<std::pair<double, double>>& bytes_seconds, double& latency,
              double& bandwidth);
// γ for a link already calibrated (model.latency, model.bandwidth): the per-pixel cost that
// minimises the squared relative error of the samples (the rest of each time, after the
// messages and bytes, over the pixels). It is an effective cost: composite.cpp's scan for
// the non-empty rectangle and its packing into messages are per pixel too.
double fit_pixel_cost(const std::vector<CompositeSample>& samples, const CompositeModel& link);
// All three by least squares on the relative error (each sample weighted by 1 / its time), none
// negative (a coefficient that would be is dropped, bandwidth 0 meaning "bytes cost nothing",
// and the rest refitted). On shared memory bytes and pixels grow together and the split between
// β and γ is ill-determined: calibrate the link by ping-pong (fit_link) where it matters.
// Throws lacuna::Error for fewer than 3 samples.
CompositeModel fit_composite_model(const std::vector<CompositeSample>& samples);

}  // namespace lacuna::dist
