#include "dist/composite_model.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "lacuna/error.h"

namespace lacuna::dist {

namespace {

constexpr double kHeader = sizeof(Rect);      // a rectangle's header message
constexpr double kPixel = 4 * sizeof(float);  // premultiplied float RGBA

// Rank 0 receives one full rectangle of `rows` rows: a header and (when not empty) its pixels.
void receive(CompositeCounts& c, int width, int rows, bool composite = true) {
    c.messages += rows > 0 ? 2 : 1;
    c.bytes += kHeader + kPixel * double(width) * double(rows);
    if (composite) c.pixels += double(width) * double(rows);
}

// The rows [r0, r1) rank `rank` keeps after the exchange rounds of composite.cpp (binary swap:
// g = 2 every round; radix-k: groups of up to k).
std::array<int, 2> final_rows(int rank, int p, int height, int k) {
    int r0 = 0, r1 = height;
    for (int unit = 1; unit < p;) {
        int g = 1;
        while (g < k && unit * g * 2 <= p) g *= 2;
        const int me = (rank / unit) % g;
        const int a0 = r0 + (r1 - r0) * me / g, a1 = r0 + (r1 - r0) * (me + 1) / g;
        r0 = a0, r1 = a1;
        unit *= g;
    }
    return {r0, r1};
}

}  // namespace

CompositeCounts composite_counts(Composite alg, int ranks, int width, int height, int k) {
    CompositeCounts c;
    const int p = swap_ranks(ranks), extras = ranks - p;
    if (alg == Composite::Direct) {
        for (int q = 0; q < ranks; ++q) {
            if (q == 0)
                c.pixels += double(width) * double(height);
            else
                receive(c, width, height);
        }
        return c;
    }
    // Binary swap is radix-k with k = 2: the same halving of rows (r0 + (r1 - r0) / 2 is the
    // radix-k split for g = 2), but it composites only the received half into its own rows
    // where radix-k composites all g pieces into a fresh accumulator.
    const int kk = alg == Composite::BinarySwap ? 2 : k;
    if (extras > 0) receive(c, width, height);  // rank 0 folds in rank P
    int r0 = 0, r1 = height;
    for (int unit = 1; unit < p;) {
        int g = 1;
        while (g < kk && unit * g * 2 <= p) g *= 2;
        const int a1 = r0 + (r1 - r0) / g;  // rank 0's digit is 0: it keeps the first part
        for (int j = 1; j < g; ++j) {
            c.messages += 2;  // header and pixels, exchanged with sendrecv
            c.bytes += kHeader + kPixel * double(width) * double(a1 - r0);
        }
        const double part = double(width) * double(a1 - r0);
        c.pixels += alg == Composite::BinarySwap ? part : part * g;
        r1 = a1;
        unit *= g;
    }
    // The gather: rank 0's own strip, then every other slot's.
    c.pixels += double(width) * double(r1 - r0);
    for (int q = 1; q < p; ++q) {
        const auto rows = final_rows(q, p, height, kk);
        receive(c, width, rows[1] - rows[0]);
    }
    return c;
}

std::string to_string(const CompositeModel& m) {
    char buf[160];
    if (m.bandwidth > 0)
        std::snprintf(buf, sizeof buf, "latency %.1f us, bandwidth %.2f GB/s, %.2f ns per pixel",
                      m.latency * 1e6, m.bandwidth * 1e-9, m.pixel_cost * 1e9);
    else
        std::snprintf(buf, sizeof buf, "latency %.1f us, bytes free, %.2f ns per pixel",
                      m.latency * 1e6, m.pixel_cost * 1e9);
    return buf;
}

void fit_link(const std::vector<std::pair<double, double>>& bytes_seconds, double& latency,
              double& bandwidth) {
    if (bytes_seconds.size() < 2)
        throw Error("composite model", "ping-pong", "expected at least 2 message sizes");
    // Minimise sum ((α + x b - t) / t)^2 over α, x = 1/β: the 2x2 normal equations.
    double s11 = 0, s12 = 0, s22 = 0, r1 = 0, r2 = 0;
    for (const auto& [b, t] : bytes_seconds) {
        if (!(t > 0)) continue;
        const double a1 = 1 / t, a2 = b / t;
        s11 += a1 * a1, s12 += a1 * a2, s22 += a2 * a2, r1 += a1, r2 += a2;
    }
    const double det = s11 * s22 - s12 * s12;
    double a = det != 0 ? (r1 * s22 - r2 * s12) / det : 0;
    double x = det != 0 ? (s11 * r2 - s12 * r1) / det : 0;
    if (a < 0) a = 0, x = s22 > 0 ? r2 / s22 : 0;  // no latency: refit the slope alone
    if (x < 0) x = 0, a = s11 > 0 ? r1 / s11 : 0;
    latency = a;
    bandwidth = x > 0 ? 1 / x : 0;
}

double fit_pixel_cost(const std::vector<CompositeSample>& samples, const CompositeModel& link) {
    CompositeModel m = link;
    m.pixel_cost = 0;
    double num = 0, den = 0;
    for (const CompositeSample& s : samples) {
        if (!(s.seconds > 0)) continue;
        const double rest = s.seconds - m.seconds(s.counts);
        num += rest * s.counts.pixels / (s.seconds * s.seconds);
        den += s.counts.pixels * s.counts.pixels / (s.seconds * s.seconds);
    }
    return den > 0 ? std::max(0.0, num / den) : 0;
}

CompositeModel fit_composite_model(const std::vector<CompositeSample>& samples) {
    if (samples.size() < 3)
        throw Error("composite model", "samples", "expected at least 3 measurements to fit");
    // Weighted least squares on x = (α, 1/β, γ): minimise sum ((a·x - t) / t)^2, by the 3x3
    // normal equations; a negative coefficient is fixed at 0 and the others refitted.
    bool active[3] = {true, true, true};
    double x[3] = {0, 0, 0};
    for (int pass = 0; pass < 4; ++pass) {
        double m[3][4] = {};
        for (const CompositeSample& s : samples) {
            if (!(s.seconds > 0)) continue;
            const double a[3] = {s.counts.messages / s.seconds, s.counts.bytes / s.seconds,
                                 s.counts.pixels / s.seconds};
            for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) m[i][j] += a[i] * a[j];
                m[i][3] += a[i];
            }
        }
        for (int i = 0; i < 3; ++i)
            if (!active[i]) {
                for (int j = 0; j < 4; ++j) m[i][j] = 0;
                for (int j = 0; j < 3; ++j) m[j][i] = 0;
                m[i][i] = 1;
            }
        // Gaussian elimination with partial pivoting.
        for (int c = 0; c < 3; ++c) {
            int piv = c;
            for (int r = c + 1; r < 3; ++r)
                if (std::abs(m[r][c]) > std::abs(m[piv][c])) piv = r;
            for (int j = 0; j < 4; ++j) std::swap(m[c][j], m[piv][j]);
            if (m[c][c] == 0) continue;
            for (int r = 0; r < 3; ++r) {
                if (r == c) continue;
                const double f = m[r][c] / m[c][c];
                for (int j = 0; j < 4; ++j) m[r][j] -= f * m[c][j];
            }
        }
        bool negative = false;
        for (int i = 0; i < 3; ++i) {
            x[i] = active[i] && m[i][i] != 0 ? m[i][3] / m[i][i] : 0;
            if (x[i] < 0) active[i] = false, negative = true;
        }
        if (!negative) break;
    }
    CompositeModel model;
    model.latency = std::max(0.0, x[0]);
    model.bandwidth = x[1] > 0 ? 1.0 / x[1] : 0;
    model.pixel_cost = std::max(0.0, x[2]);
    return model;
}

}  // namespace lacuna::dist
