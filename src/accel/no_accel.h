// --accel none: the reference. Its cursor returns the ray's whole box interval once.
#pragma once
#include "accel/cursor.h"
#include "lacuna/accel.h"

namespace lacuna {

class NoAccel final : public Accel {
  public:
    NoAccel() : Accel(AccelKind::None) {}
    void set_transfer_function(const TransferLut&) override {}

    class Cursor {
      public:
        Cursor(const NoAccel&, const IndexRay&, float t_near, float t_far, float = 0.f, float = 0.f)
            : m_seg{t_near, t_far} {}
        bool next(Segment& out) {
            if (m_done) return false;
            m_done = true;
            out = m_seg;
            return true;
        }

      private:
        Segment m_seg;
        bool m_done = false;
    };
};

}  // namespace lacuna
