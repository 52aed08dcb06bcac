// Builds NIfTI-1/2 files byte by byte for the reader tests (layouts in
// src/io/nifti_reader.cpp), and gzips buffers.
#pragma once
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "lacuna/math.h"

namespace lacuna::test {

struct NiftiSpec {
    int version = 1;
    int ndim = 3;
    Vec3i dims{2, 2, 2};
    int64_t dim4 = 1, dim5 = 1;
    int datatype = 2;
    int bitpix = 0;  // 0: derived from datatype
    Vec3d pixdim{1, 1, 1};
    double slope = 0, inter = 0;
    int qform_code = 0, sform_code = 0;
    std::array<std::array<double, 4>, 3> srow{};
    std::array<double, 3> quatern{}, qoffset{};  // quatern_b/c/d, qoffset_x/y/z
    double qfac = 1;                             // pixdim[0]
    bool big_endian = false;
    std::string magic;       // "" = the right one for the version
    int64_t vox_offset = 0;  // 0 = right after the header (+4 extension bytes)
};

inline int nifti_bitpix(int datatype) {
    switch (datatype) {
        case 2:
        case 256:
            return 8;
        case 4:
        case 512:
            return 16;
        case 8:
        case 16:
        case 768:
            return 32;
        case 64:
        case 1024:
        case 1280:
        case 32:
            return 64;
        case 128:
            return 24;
        case 2304:
            return 32;
        default:
            return 8;
    }
}

inline std::vector<uint8_t> nifti_bytes(const NiftiSpec& s, const void* voxels, size_t bytes) {
    const size_t hdr = s.version == 1 ? 348 : 540;
    const int64_t off = s.vox_offset ? s.vox_offset : int64_t(hdr + 4);
    std::vector<uint8_t> out(size_t(std::max<int64_t>(off, int64_t(hdr))) + bytes, 0);
    auto put = [&](size_t at, auto value) {
        std::memcpy(out.data() + at, &value, sizeof value);
        if (s.big_endian)
            std::reverse(out.begin() + long(at), out.begin() + long(at + sizeof value));
    };
    const int64_t dim[8] = {s.ndim, s.dims.x, s.dims.y, s.dims.z, s.dim4, s.dim5, 1, 1};
    const double pix[8] = {s.qfac, s.pixdim.x, s.pixdim.y, s.pixdim.z, 1, 1, 1, 1};
    const int bitpix = s.bitpix ? s.bitpix : nifti_bitpix(s.datatype);
    if (s.version == 1) {
        put(0, int32_t(348));
        for (int i = 0; i < 8; ++i) put(40 + 2 * i, int16_t(dim[i]));
        put(70, int16_t(s.datatype));
        put(72, int16_t(bitpix));
        for (int i = 0; i < 8; ++i) put(76 + 4 * i, float(pix[i]));
        put(108, float(off));
        put(112, float(s.slope));
        put(116, float(s.inter));
        put(252, int16_t(s.qform_code));
        put(254, int16_t(s.sform_code));
        for (int i = 0; i < 3; ++i) put(256 + 4 * i, float(s.quatern[i]));
        for (int i = 0; i < 3; ++i) put(268 + 4 * i, float(s.qoffset[i]));
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) put(280 + 16 * r + 4 * c, float(s.srow[r][c]));
        const std::string magic = s.magic.empty() ? std::string("n+1\0", 4) : s.magic;
        std::memcpy(out.data() + 344, magic.data(), std::min<size_t>(4, magic.size()));
    } else {
        put(0, int32_t(540));
        const std::string magic = s.magic.empty() ? std::string("n+2\0\r\n\032\n", 8) : s.magic;
        std::memcpy(out.data() + 4, magic.data(), std::min<size_t>(8, magic.size()));
        put(12, int16_t(s.datatype));
        put(14, int16_t(bitpix));
        for (int i = 0; i < 8; ++i) put(16 + 8 * i, int64_t(dim[i]));
        for (int i = 0; i < 8; ++i) put(104 + 8 * i, pix[i]);
        put(168, int64_t(off));
        put(176, s.slope);
        put(184, s.inter);
        put(344, int32_t(s.qform_code));
        put(348, int32_t(s.sform_code));
        for (int i = 0; i < 3; ++i) put(352 + 8 * i, s.quatern[i]);
        for (int i = 0; i < 3; ++i) put(376 + 8 * i, s.qoffset[i]);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) put(400 + 32 * r + 8 * c, s.srow[r][c]);
    }
    if (bytes) std::memcpy(out.data() + (out.size() - bytes), voxels, bytes);
    return out;
}

inline std::vector<uint8_t> gzip(const std::vector<uint8_t>& in) {
    z_stream z{};
    deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);  // +16: gzip wrapper
    std::vector<uint8_t> out(deflateBound(&z, uLong(in.size())) + 64);
    z.next_in = const_cast<Bytef*>(in.data());
    z.avail_in = uInt(in.size());
    z.next_out = out.data();
    z.avail_out = uInt(out.size());
    deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

}  // namespace lacuna::test
