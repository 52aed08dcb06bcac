#include "accel/summed_volume_table.h"

namespace lacuna {

template <class Count>
void SummedVolumeTable<Count>::build_eq5() {
    const int nx = m_n[0], ny = m_n[1], nz = m_n[2];
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                // Eq. 5: the current V1 and seven V2 values computed before it.
                Count& v = m_v[index(i, j, k)];
                v = v + at(i, j, k - 1) + (at(i - 1, j, k) - at(i - 1, j, k - 1)) +
                    (at(i, j - 1, k) - at(i, j - 1, k - 1)) -
                    (at(i - 1, j - 1, k) - at(i - 1, j - 1, k - 1));
            }
}

template <class Count>
void SummedVolumeTable<Count>::build_from_row_sums() {
    const int nx = m_n[0], ny = m_n[1], nz = m_n[2];
    Count* v = m_v.data();
    const size_t sy = m_sy, sz = m_sz;
    // One sequential pass, whole rows: the three earlier rows are in cache (the row above and
    // the plane behind), and the loop over i is a plain vector add. Parallel variants (chunks
    // of x per thread) measured 3-5x slower on 256^3: the pass is memory bound and the strided
    // chunk walks defeat the prefetcher.
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j) {
            Count* cur = v + size_t(k) * sz + size_t(j) * sy;
            if (j > 0 && k > 0) {
                const Count* up = cur - sy;     // V2(., j-1, k)
                const Count* back = cur - sz;   // V2(., j, k-1)
                const Count* diag = back - sy;  // V2(., j-1, k-1)
                for (int i = 0; i < nx; ++i) cur[i] += up[i] + back[i] - diag[i];
            } else if (j > 0) {
                const Count* up = cur - sy;
                for (int i = 0; i < nx; ++i) cur[i] += up[i];
            } else if (k > 0) {
                const Count* back = cur - sz;
                for (int i = 0; i < nx; ++i) cur[i] += back[i];
            }
        }
}

template class SummedVolumeTable<uint32_t>;
template class SummedVolumeTable<uint64_t>;

}  // namespace lacuna
