// Sort-last compositing of the ranks' partial images (docs/distributed.md, "Compositing").
//
// Each rank's partial is the premultiplied float RGBA (r, g, b, a per pixel, row-major, before
// the background and the 8-bit rounding: FrameResult::rgba_float) of its owned samples, composited
// front to back from zero as the single-process ray does. Along a ray the bricks follow in the
// kd-tree's visibility order (decomposition.h), so the ray's colour is the partials combined with
// Porter-Duff over in that order:
//     front over back = front + (1 - front.a) * back    (per channel, premultiplied)
// which is the single-process accumulation regrouped: the only difference is float association
// (a ray's samples a1..an summed as (a1..am) over (am+1..an) instead of one chain), which moves a
// channel by a few ulps, far below the 1/255 of the 8-bit pixel (tests/dist/).
//
// Each rank sends only the bounding rectangle of its non-empty pixels (zero RGBA elsewhere, which
// over leaves unchanged: 0 over x = x and x over 0 = x exactly).
//   direct       every rank sends its rectangle to rank 0, which composites them in order.
//   binary swap  (Ma et al. 1994, IceT's): log2 P rounds; in round b the two ranks whose slots
//                differ in bit b (the two subtrees of one kd node, decomposition.h) split their
//                current rows in halves, each sends the half it gives up and composites the half
//                it keeps in the node's order; then rank 0 gathers the P strips. A rank beyond P
//                first folds into its sibling (slot s < N - P).
//   radix-k      (Peterka et al. 2009, IceT's default): binary swap with rounds of k ranks
//                instead of 2. P = k1 * k2 * ...; in round i the k_i ranks whose slots differ
//                only in digit i (an aligned block of slots: a subtree of the kd-tree) split their
//                rows in k_i parts, each keeps one and receives that part from the k_i - 1 others
//                (k_i - 1 exchanges, partner = index XOR j), and composites the k_i pieces in the
//                subtree's visibility order. k = 2 is binary swap; the default k is 4.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "dist/comm.h"
#include "dist/decomposition.h"

namespace lacuna::dist {

enum class Composite { Direct, BinarySwap, RadixK };
std::string to_string(Composite c);

// A rectangle of pixels [x0, x1) x [y0, y1); empty when x0 >= x1 or y0 >= y1.
struct Rect {
    int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
    int64_t pixels() const { return empty() ? 0 : int64_t(x1 - x0) * int64_t(y1 - y0); }
};

// The premultiplied RGBA of a width x height image.
struct Partial {
    int width = 0, height = 0;
    std::vector<float> rgba;  // 4 floats per pixel, row-major
    float* at(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
    const float* at(int x, int y) const {
        return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
    }
};

// The bounding rectangle of the pixels of `within` that hold a non-zero channel.
Rect nonempty_rect(const Partial& p, const Rect& within);
// The pixels of `r` of `p`, row by row (4 floats each).
std::vector<float> pack(const Partial& p, const Rect& r);
// dst = src over dst (src_in_front) or dst over src, on the pixels of `r`, src packed as pack().
void composite_into(Partial& dst, const Rect& r, const float* src, bool src_in_front);

struct CompositeStats {
    uint64_t bytes_sent = 0;
    double seconds = 0;
    // What this rank received and composited (the regressors of composite_model.h): messages
    // (a rectangle's header and its pixels are two), their bytes, and the pixels it put through
    // over (composite_into).
    uint64_t messages_received = 0, bytes_received = 0, pixels_composited = 0;
};

// Rank 0 gets the composited image (every rank passes its partial); the other ranks an empty
// Partial. `order`: the ranks front to back (visibility_order).
Partial composite_direct(Comm& comm, const Partial& mine, const std::vector<int>& order,
                         CompositeStats& stats);
// The same by binary swap over the decomposition's tree; `eye`, `dir`, `orthographic` as for
// visibility_order.
Partial composite_binary_swap(Comm& comm, Partial mine, const Decomposition& d, Vec3f eye,
                              Vec3f dir, bool orthographic, CompositeStats& stats);

// The same by radix-k with rounds of `k` ranks (a power of two >= 2; the last round takes what
// divides what is left).
Partial composite_radix_k(Comm& comm, Partial mine, const Decomposition& d, Vec3f eye, Vec3f dir,
                          bool orthographic, int k, CompositeStats& stats);
// The slot blocks of size `unit` in slots [a, b) (b - a a power-of-two multiple of `unit`) front
// to back: the kd-tree's visibility order of the subtree, by block index (a / unit, ...).
std::vector<int> block_order(const Decomposition& d, int a, int b, int unit, Vec3f eye, Vec3f dir,
                             bool orthographic);

}  // namespace lacuna::dist
