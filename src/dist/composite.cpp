#include "dist/composite.h"

#include <algorithm>
#include <chrono>

namespace lacuna::dist {

std::string to_string(Composite c) {
    switch (c) {
        case Composite::Direct:
            return "direct";
        case Composite::BinarySwap:
            return "binary-swap";
        case Composite::RadixK:
            return "radix-k";
    }
    return "?";
}

Rect nonempty_rect(const Partial& p, const Rect& within) {
    Rect r{within.x1, within.y1, within.x0, within.y0};  // inverted: empty until a pixel is found
    for (int y = within.y0; y < within.y1; ++y)
        for (int x = within.x0; x < within.x1; ++x) {
            const float* c = p.at(x, y);
            if (c[0] != 0.f || c[1] != 0.f || c[2] != 0.f || c[3] != 0.f) {
                r.x0 = std::min(r.x0, x), r.x1 = std::max(r.x1, x + 1);
                r.y0 = std::min(r.y0, y), r.y1 = std::max(r.y1, y + 1);
            }
        }
    if (r.empty()) return Rect{};
    return r;
}

std::vector<float> pack(const Partial& p, const Rect& r) {
    std::vector<float> out(size_t(r.pixels()) * 4);
    if (r.empty()) return out;
    const size_t row = size_t(r.x1 - r.x0) * 4;
    for (int y = r.y0; y < r.y1; ++y) std::copy_n(p.at(r.x0, y), row, &out[size_t(y - r.y0) * row]);
    return out;
}

void composite_into(Partial& dst, const Rect& r, const float* src, bool src_in_front) {
    if (r.empty()) return;
    const int w = r.x1 - r.x0;
    for (int y = r.y0; y < r.y1; ++y) {
        float* d = dst.at(r.x0, y);
        const float* s = src + size_t(y - r.y0) * size_t(w) * 4;
        for (int x = 0; x < w; ++x, d += 4, s += 4) {
            // front + (1 - front.a) * back, per premultiplied channel
            const float* f = src_in_front ? s : d;
            const float* b = src_in_front ? d : s;
            const float k = 1.f - f[3];
            const float o[4] = {f[0] + k * b[0], f[1] + k * b[1], f[2] + k * b[2], f[3] + k * b[3]};
            std::copy_n(o, 4, d);
        }
    }
}

namespace {

using Clock = std::chrono::steady_clock;

// Tags of the messages, one per round kind.
constexpr int kTagDirect = 100, kTagFold = 200, kTagSwap = 300, kTagGather = 400;

// Sends the rectangle's header, then its pixels.
void send_rect(Comm& comm, int to, int tag, const Partial& p, const Rect& r, CompositeStats& st) {
    comm.send(to, tag, &r, sizeof r);
    st.bytes_sent += sizeof r;
    if (r.empty()) return;
    const std::vector<float> px = pack(p, r);
    comm.send(to, tag + 1, px.data(), px.size() * sizeof(float));
    st.bytes_sent += px.size() * sizeof(float);
}

// Receives a header and its pixels.
Rect recv_rect(Comm& comm, int from, int tag, std::vector<float>& px, CompositeStats& st) {
    Rect r;
    comm.recv(from, tag, &r, sizeof r);
    px.assign(size_t(r.pixels()) * 4, 0.f);
    st.messages_received += 1, st.bytes_received += sizeof r;
    if (!r.empty()) {
        comm.recv(from, tag + 1, px.data(), px.size() * sizeof(float));
        st.messages_received += 1, st.bytes_received += px.size() * sizeof(float);
    }
    return r;
}

// composite_into, counted.
void over(Partial& dst, const Rect& r, const float* src, bool src_in_front, CompositeStats& st) {
    composite_into(dst, r, src, src_in_front);
    st.pixels_composited += uint64_t(r.pixels());
}

}  // namespace

Partial composite_direct(Comm& comm, const Partial& mine, const std::vector<int>& order,
                         CompositeStats& st) {
    const auto t0 = Clock::now();
    const Rect whole{0, 0, mine.width, mine.height};
    Partial out;
    if (comm.rank() != 0) {
        send_rect(comm, 0, kTagDirect, mine, nonempty_rect(mine, whole), st);
    } else {
        out.width = mine.width, out.height = mine.height;
        out.rgba.assign(mine.rgba.size(), 0.f);
        std::vector<float> px;
        // Front to back: each partial goes behind what is composited so far.
        for (int q : order) {
            if (q == 0) {
                const Rect r = nonempty_rect(mine, whole);
                const std::vector<float> own = pack(mine, r);
                over(out, r, own.data(), false, st);
                continue;
            }
            const Rect r = recv_rect(comm, q, kTagDirect, px, st);
            over(out, r, px.data(), false, st);
        }
    }
    st.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    return out;
}

// Step 1 of binary swap and radix-k: with N = P + extras ranks (P a power of two), rank P + s
// sends its non-empty rectangle to rank s, which composites it in its pair's visibility order
// (child 0, the low side, is rank s). True on the ranks that sent: they are done.
static bool fold_extras(Comm& comm, Partial& mine, const Decomposition& d, Vec3f eye, Vec3f dir,
                        bool orthographic, CompositeStats& st) {
    const int rank = comm.rank(), p = swap_ranks(comm.size()), extras = comm.size() - p;
    if (rank >= p) {
        send_rect(comm, rank - p, kTagFold, mine,
                  nonempty_rect(mine, Rect{0, 0, mine.width, mine.height}), st);
        return true;
    }
    if (rank < extras) {
        std::vector<float> px;
        const KdNode& pair = d.nodes[size_t(slot_node(d, rank, rank + 1))];
        const Rect r = recv_rect(comm, rank + p, kTagFold, px, st);
        over(mine, r, px.data(), !low_in_front(pair, eye, dir, orthographic), st);
    }
    return false;
}

Partial composite_binary_swap(Comm& comm, Partial mine, const Decomposition& d, Vec3f eye,
                              Vec3f dir, bool orthographic, CompositeStats& st) {
    const auto t0 = Clock::now();
    const int n = comm.size(), rank = comm.rank();
    const int p = swap_ranks(n);
    auto done = [&](Partial result) {
        st.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
        return result;
    };
    // 1. The ranks beyond P fold into their siblings (slot s: ranks s and P + s).
    if (fold_extras(comm, mine, d, eye, dir, orthographic, st)) return done(Partial{});
    std::vector<float> px;
    // 2. log2 P rounds over rows: the lower slot of a pair keeps the upper rows of the region.
    int r0 = 0, r1 = mine.height;
    for (int bit = 1; bit < p; bit *= 2) {
        const int partner = rank ^ bit;
        const int a = rank & ~(2 * bit - 1);
        const KdNode& node = d.nodes[size_t(slot_node(d, a, a + 2 * bit))];
        const bool i_am_low = (rank & bit) == 0;  // in child 0
        const bool low_front = low_in_front(node, eye, dir, orthographic);
        const bool partner_front = i_am_low ? !low_front : low_front;
        const int mid = r0 + (r1 - r0) / 2;
        const Rect keep = i_am_low ? Rect{0, r0, mine.width, mid} : Rect{0, mid, mine.width, r1};
        const Rect give = i_am_low ? Rect{0, mid, mine.width, r1} : Rect{0, r0, mine.width, mid};
        // Exchange the headers, then the pixels.
        const Rect out_r = give.empty() ? Rect{} : nonempty_rect(mine, give);
        Rect in_r;
        comm.sendrecv(partner, kTagSwap, &out_r, sizeof out_r, &in_r, sizeof in_r);
        const std::vector<float> out_px = pack(mine, out_r);
        px.assign(size_t(in_r.pixels()) * 4, 0.f);
        comm.sendrecv(partner, kTagSwap + 1, out_px.data(), out_px.size() * sizeof(float),
                      px.data(), px.size() * sizeof(float));
        st.bytes_sent += sizeof out_r + out_px.size() * sizeof(float);
        st.messages_received += 2, st.bytes_received += sizeof in_r + px.size() * sizeof(float);
        over(mine, in_r, px.data(), partner_front, st);
        r0 = keep.y0, r1 = keep.y1;
    }
    // 3. Rank 0 gathers the strips.
    const Rect strip{0, r0, mine.width, r1};
    if (rank != 0) {
        send_rect(comm, 0, kTagGather, mine, strip.empty() ? Rect{} : nonempty_rect(mine, strip),
                  st);
        return done(Partial{});
    }
    Partial out;
    out.width = mine.width, out.height = mine.height;
    out.rgba.assign(mine.rgba.size(), 0.f);
    const std::vector<float> own = pack(mine, strip);
    over(out, strip, own.data(), true, st);
    for (int q = 1; q < p; ++q) {
        const Rect r = recv_rect(comm, q, kTagGather, px, st);
        over(out, r, px.data(), true, st);  // over zero: a copy
    }
    return done(std::move(out));
}

std::vector<int> block_order(const Decomposition& d, int a, int b, int unit, Vec3f eye, Vec3f dir,
                             bool orthographic) {
    if (b - a <= unit) return {a / unit};
    const KdNode& n = d.nodes[size_t(slot_node(d, a, b))];
    const int mid = a + (b - a) / 2;
    std::vector<int> lo = block_order(d, a, mid, unit, eye, dir, orthographic);
    std::vector<int> hi = block_order(d, mid, b, unit, eye, dir, orthographic);
    if (!low_in_front(n, eye, dir, orthographic)) std::swap(lo, hi);
    lo.insert(lo.end(), hi.begin(), hi.end());
    return lo;
}

Partial composite_radix_k(Comm& comm, Partial mine, const Decomposition& d, Vec3f eye, Vec3f dir,
                          bool orthographic, int k, CompositeStats& st) {
    const auto t0 = Clock::now();
    const int n = comm.size(), rank = comm.rank();
    const int p = swap_ranks(n);
    auto done = [&](Partial result) {
        st.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
        return result;
    };
    // 1. The ranks beyond P fold into their siblings as in binary swap.
    if (fold_extras(comm, mine, d, eye, dir, orthographic, st)) return done(Partial{});
    std::vector<float> px;
    // 2. Rounds of g ranks: the slots of an aligned block of unit * g slots that differ only in
    // their digit (slot / unit) % g; the part of the rows a rank keeps is its digit's.
    int r0 = 0, r1 = mine.height;
    Partial acc{mine.width, mine.height, std::vector<float>(mine.rgba.size(), 0.f)};
    for (int unit = 1; unit < p;) {
        int g = 1;
        while (g < k && unit * g * 2 <= p) g *= 2;
        const int a = rank - rank % (unit * g);
        const int me = (rank / unit) % g;
        auto part = [&](int q) {
            return Rect{0, r0 + (r1 - r0) * q / g, mine.width, r0 + (r1 - r0) * (q + 1) / g};
        };
        // The g pieces of my part, by digit: mine, and the others' by one exchange with all
        // g - 1 peers at once (Comm::exchange): first the rectangles, then their pixels.
        const size_t gs = size_t(g);
        std::vector<Rect> rects(gs), out_r(gs);
        std::vector<std::vector<float>> pieces(gs), out_px(gs);
        const Rect keep = part(me);
        rects[size_t(me)] = keep.empty() ? Rect{} : nonempty_rect(mine, keep);
        pieces[size_t(me)] = pack(mine, rects[size_t(me)]);
        auto peer_of = [&](int other) { return a + other * unit + rank % unit; };
        std::vector<Comm::Transfer> t;
        for (int other = 0; other < g; ++other) {
            if (other == me) continue;
            const Rect give = part(other);
            out_r[size_t(other)] = give.empty() ? Rect{} : nonempty_rect(mine, give);
            t.push_back({peer_of(other), &out_r[size_t(other)], sizeof(Rect), &rects[size_t(other)],
                         sizeof(Rect)});
        }
        comm.exchange(kTagSwap, t);
        t.clear();
        for (int other = 0; other < g; ++other) {
            if (other == me) continue;
            const size_t o = size_t(other);
            out_px[o] = pack(mine, out_r[o]);
            pieces[o].assign(size_t(rects[o].pixels()) * 4, 0.f);
            t.push_back({peer_of(other), out_px[o].data(), out_px[o].size() * sizeof(float),
                         pieces[o].data(), pieces[o].size() * sizeof(float)});
            st.bytes_sent += sizeof(Rect) + out_px[o].size() * sizeof(float);
            st.messages_received += 2,
                st.bytes_received += sizeof(Rect) + pieces[o].size() * sizeof(float);
        }
        comm.exchange(kTagSwap + 1, t);
        // Front to back over zero in the block's visibility order, then back into `mine`.
        for (int y = keep.y0; y < keep.y1; ++y)
            std::fill_n(acc.at(0, y), size_t(mine.width) * 4, 0.f);
        for (int q : block_order(d, a, a + unit * g, unit, eye, dir, orthographic)) {
            const int digit = q - a / unit;
            over(acc, rects[size_t(digit)], pieces[size_t(digit)].data(), false, st);
        }
        for (int y = keep.y0; y < keep.y1; ++y)
            std::copy_n(acc.at(0, y), size_t(mine.width) * 4, mine.at(0, y));
        r0 = keep.y0, r1 = keep.y1;
        unit *= g;
    }
    // 3. Rank 0 gathers the strips.
    const Rect strip{0, r0, mine.width, r1};
    if (rank != 0) {
        send_rect(comm, 0, kTagGather, mine, strip.empty() ? Rect{} : nonempty_rect(mine, strip),
                  st);
        return done(Partial{});
    }
    Partial out;
    out.width = mine.width, out.height = mine.height;
    out.rgba.assign(mine.rgba.size(), 0.f);
    const std::vector<float> own = pack(mine, strip);
    over(out, strip, own.data(), true, st);
    for (int q = 1; q < p; ++q) {
        const Rect r = recv_rect(comm, q, kTagGather, px, st);
        over(out, r, px.data(), true, st);
    }
    return done(std::move(out));
}

}  // namespace lacuna::dist
