// Test helper: a random orthogonal BSP partition of a volume's cells as a BoxSource.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/rng.h"
#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"
#include "slice/box_source.h"

namespace lacuna::test {

// A random orthogonal BSP tree over the cells: every leaf a box; leaves whose cells are all
// transparent under the LUT (by the 8 corners' min and max, as the structures classify) are
// dropped. Front to back by the tree: the near child of every split first.
class RandomBspSource final : public BoxSource {
  public:
    RandomBspSource(const Volume& v, uint64_t seed, int depth) : m_volume(v) {
        Rng rng{seed};
        m_nodes.push_back({{{0, 0, 0}, {v.dims().x - 1, v.dims().y - 1, v.dims().z - 1}}});
        split(0, rng, depth);
    }
    void set_transfer_function(const TransferLut& lut) override {
        const ValueToLut map = lut.map();
        for (Node& n : m_nodes) {
            if (n.left >= 0) continue;
            n.visible = false;
            for (int k = n.box.lo[2]; k < n.box.hi[2] && !n.visible; ++k)
                for (int j = n.box.lo[1]; j < n.box.hi[1] && !n.visible; ++j)
                    for (int i = n.box.lo[0]; i < n.box.hi[0] && !n.visible; ++i) {
                        float lo = INFINITY, hi = -INFINITY;
                        for (int c = 0; c < 8; ++c) {
                            const float x =
                                m_volume.value(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2));
                            lo = std::min(lo, x);
                            hi = std::max(hi, x);
                        }
                        for (int e = map(lo); e <= map(hi); ++e)
                            if (lut.entries[size_t(e)].a > 0.f) n.visible = true;
                    }
        }
    }
    std::vector<CellBox> boxes_front_to_back(Vec3f eye) const override {
        std::vector<CellBox> out;
        walk(
            0, [&](const Node& n) { return eye[n.axis] < float(n.plane); }, out);
        return out;
    }
    std::vector<CellBox> boxes_front_to_back_along(Vec3f dir) const override {
        std::vector<CellBox> out;
        walk(
            0, [&](const Node& n) { return dir[n.axis] > 0.f; }, out);
        return out;
    }
    const char* name() const override { return "random-bsp"; }
    size_t leaves() const {
        size_t n = 0;
        for (const Node& x : m_nodes) n += x.left < 0;
        return n;
    }

  private:
    struct Node {
        CellBox box;
        int axis = -1, plane = 0, left = -1;
        bool visible = true;
    };
    void split(int i, Rng& rng, int depth) {
        const CellBox b = m_nodes[size_t(i)].box;
        const int a = rng.range(0, 2);
        if (depth == 0 || b.hi[a] - b.lo[a] < 2) return;
        const int p = rng.range(b.lo[a] + 1, b.hi[a] - 1);
        Node l{b}, r{b};
        l.box.hi[a] = p;
        r.box.lo[a] = p;
        const int li = int(m_nodes.size());
        m_nodes[size_t(i)].axis = a;
        m_nodes[size_t(i)].plane = p;
        m_nodes[size_t(i)].left = li;
        m_nodes.push_back(l);
        m_nodes.push_back(r);
        split(li, rng, depth - 1);
        split(li + 1, rng, depth - 1);
    }
    template <class NearLeft>
    void walk(int i, const NearLeft& near_left, std::vector<CellBox>& out) const {
        const Node& n = m_nodes[size_t(i)];
        if (n.left < 0) {
            if (n.visible) out.push_back(n.box);
            return;
        }
        const bool l = near_left(n);
        walk(l ? n.left : n.left + 1, near_left, out);
        walk(l ? n.left + 1 : n.left, near_left, out);
    }
    const Volume& m_volume;
    std::vector<Node> m_nodes;
};

}  // namespace lacuna::test
