// NIfTI-1 and NIfTI-2 single-file reader (.nii, .nii.gz).
//
// Why not ITK: ITK 5.2's NiftiImageIO only knows NIfTI-1, and its Read() loads the whole image
// into niftilib's own buffer and then copies it into ours (a second full-size copy). The format
// is small enough to parse directly: a fixed binary header, then voxels at vox_offset.
// zlib's gz* functions read gzip-compressed and plain files alike.
//
// Header layouts (byte offsets; NIfTI-1 header is 348 bytes, NIfTI-2 is 540):
//   field        NIfTI-1          NIfTI-2
//   sizeof_hdr   0   int32        0   int32
//   magic        344 char[4]      4   char[8]
//   datatype     70  int16        12  int16
//   bitpix       72  int16        14  int16
//   dim[8]       40  int16        16  int64
//   pixdim[8]    76  float        104 double
//   vox_offset   108 float        168 int64
//   scl_slope    112 float        176 double
//   scl_inter    116 float        184 double
//   qform_code   252 int16        344 int32
//   sform_code   254 int16        348 int32
//   quatern_bcd  256 float[3]     352 double[3]
//   qoffset_xyz  268 float[3]     376 double[3]
//   srow_x/y/z   280 float[4]x3   400 double[4]x3
//
// Geometry is chosen as ITK's NiftiImageIO chooses it (see set_geometry) and converted from NIfTI's
// RAS+ world to ITK's LPS+ (negate x and y), so origin/direction agree with ITK-based tools and
// with the NRRD/MetaImage readers.
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include "io/io_util.h"
#include "io/readers.h"
#include "io/rgb_volume.h"
#include "lacuna/error.h"
#include "lacuna/orientation.h"

namespace lacuna::io {

namespace {

struct GzCloser {
    void operator()(gzFile_s* f) const { gzclose(f); }
};
using GzFile = std::unique_ptr<gzFile_s, GzCloser>;

struct NiftiHeader {
    int version = 1;
    bool swap = false;
    int64_t dim[8] = {};
    int datatype = 0;
    int bitpix = 0;
    double pixdim[8] = {};
    int64_t vox_offset = 0;
    double slope = 0, inter = 0;
    int qform_code = 0, sform_code = 0;
    double quatern[3] = {}, qoffset[3] = {};
    double srow[3][4] = {};
};

// Reads a T at byte `off` of the header, fixing byte order.
template <class T>
T get(const uint8_t* buf, size_t off, bool swap) {
    T v;
    std::memcpy(&v, buf + off, sizeof(T));
    if (swap) swap_bytes(&v, 1, sizeof(T));
    return v;
}

// gzerror's text, without the "<path>: " it starts with.
std::string zlib_reason(const char* msg, const std::string& path) {
    std::string s = msg ? msg : "zlib error";
    if (s.rfind(path + ": ", 0) == 0) s.erase(0, path.size() + 2);
    return one_line(s);
}

// Fills `out` from the stream; returns the number of bytes read. Treats a truncated gzip
// member as end of data (the caller reports truncation with byte counts); throws on corrupt
// compressed data.
size_t gz_read_all(gzFile f, void* out, size_t n, const std::string& path) {
    auto* dst = static_cast<uint8_t*>(out);
    size_t done = 0;
    while (done < n) {
        // gzread takes an unsigned int; stay well inside it.
        const unsigned want = unsigned(std::min<size_t>(n - done, size_t(1) << 30));
        const int got = gzread(f, dst + done, want);
        if (got < 0) {
            int code = 0;
            const char* msg = gzerror(f, &code);
            if (code == Z_BUF_ERROR) break;  // "unexpected end of file": truncated
            throw Error(path, "voxel data", "corrupt compressed data: " + zlib_reason(msg, path));
        }
        if (got == 0) {
            int code = 0;
            const char* msg = gzerror(f, &code);
            if (code != Z_OK && code != Z_BUF_ERROR)
                throw Error(path, "voxel data",
                            "corrupt compressed data: " + zlib_reason(msg, path));
            break;
        }
        done += size_t(got);
    }
    return done;
}

// `pair`: the header of a two-file NIfTI (.hdr beside its .img), whose magic is ni1 / ni2 and
// whose vox_offset counts from the start of the .img; otherwise a one-file .nii (n+1 / n+2).
NiftiHeader parse_header(gzFile f, const std::string& path, bool pair) {
    uint8_t buf[540] = {};
    const size_t got = gz_read_all(f, buf, 348, path);
    if (got < 4) throw Error(path, "header", "not a NIfTI file (file is too short)");
    NiftiHeader h;
    const int32_t size_native = get<int32_t>(buf, 0, false);
    const int32_t size_swapped = get<int32_t>(buf, 0, true);
    if (size_native == 348 || size_native == 540) {
        h.version = size_native == 348 ? 1 : 2;
    } else if (size_swapped == 348 || size_swapped == 540) {
        h.version = size_swapped == 348 ? 1 : 2;
        h.swap = true;
    } else {
        throw Error(path, "header",
                    "not a NIfTI file (header size field is " + std::to_string(size_native) +
                        ", expected 348 or 540)");
    }
    const size_t hdr_size = h.version == 1 ? 348 : 540;
    size_t have = got;
    if (h.version == 2 && have == 348) have += gz_read_all(f, buf + 348, 540 - 348, path);
    if (have < hdr_size)
        throw Error(path, "header",
                    "truncated: a NIfTI-" + std::to_string(h.version) + " header needs " +
                        std::to_string(hdr_size) + " bytes, the file has " + std::to_string(have));
    const bool s = h.swap;
    if (h.version == 1) {
        const char* magic = reinterpret_cast<const char*>(buf + 344);
        if (!pair && std::memcmp(magic, "ni1\0", 4) == 0)
            throw Error(path, "header",
                        "the header says its voxels are in a separate .img file (magic 'ni1'): "
                        "name it .hdr beside its .img");
        if (std::memcmp(magic, pair ? "ni1\0" : "n+1\0", 4) != 0)
            throw Error(
                path, "header",
                pair ? "not a NIfTI-1 pair header (magic 'ni1' missing; Analyze 7.5 headers "
                       "are not read: their orientation is not in the file)"
                     : "not a NIfTI-1 file (magic 'n+1' missing; Analyze 7.5 is not supported)");
        for (int i = 0; i < 8; ++i) h.dim[i] = get<int16_t>(buf, 40 + 2 * i, s);
        h.datatype = get<int16_t>(buf, 70, s);
        h.bitpix = get<int16_t>(buf, 72, s);
        for (int i = 0; i < 8; ++i) h.pixdim[i] = get<float>(buf, 76 + 4 * i, s);
        const double off = get<float>(buf, 108, s);
        if (!std::isfinite(off) || off < 0 || off > 1e15)
            throw Error(path, "header", "invalid vox_offset " + std::to_string(off));
        h.vox_offset = int64_t(off);
        h.slope = get<float>(buf, 112, s);
        h.inter = get<float>(buf, 116, s);
        h.qform_code = get<int16_t>(buf, 252, s);
        h.sform_code = get<int16_t>(buf, 254, s);
        for (int i = 0; i < 3; ++i) h.quatern[i] = get<float>(buf, 256 + 4 * i, s);
        for (int i = 0; i < 3; ++i) h.qoffset[i] = get<float>(buf, 268 + 4 * i, s);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) h.srow[r][c] = get<float>(buf, 280 + 16 * r + 4 * c, s);
    } else {
        const char* magic = reinterpret_cast<const char*>(buf + 4);
        if (!pair && std::memcmp(magic, "ni2\0", 4) == 0)
            throw Error(path, "header",
                        "the header says its voxels are in a separate .img file (magic 'ni2'): "
                        "name it .hdr beside its .img");
        if (std::memcmp(magic, pair ? "ni2\0" : "n+2\0", 4) != 0)
            throw Error(path, "header",
                        pair ? "not a NIfTI-2 pair header (magic 'ni2' missing)"
                             : "not a NIfTI-2 file (magic 'n+2' missing)");
        h.datatype = get<int16_t>(buf, 12, s);
        h.bitpix = get<int16_t>(buf, 14, s);
        for (int i = 0; i < 8; ++i) h.dim[i] = get<int64_t>(buf, 16 + 8 * i, s);
        for (int i = 0; i < 8; ++i) h.pixdim[i] = get<double>(buf, 104 + 8 * i, s);
        h.vox_offset = get<int64_t>(buf, 168, s);
        h.slope = get<double>(buf, 176, s);
        h.inter = get<double>(buf, 184, s);
        h.qform_code = get<int32_t>(buf, 344, s);
        h.sform_code = get<int32_t>(buf, 348, s);
        for (int i = 0; i < 3; ++i) h.quatern[i] = get<double>(buf, 352 + 8 * i, s);
        for (int i = 0; i < 3; ++i) h.qoffset[i] = get<double>(buf, 376 + 8 * i, s);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) h.srow[r][c] = get<double>(buf, 400 + 32 * r + 8 * c, s);
    }
    if (!pair && h.vox_offset < int64_t(hdr_size))
        throw Error(path, "header",
                    "vox_offset " + std::to_string(h.vox_offset) +
                        " points inside the header (expected >= " + std::to_string(hdr_size) + ")");
    return h;
}

// NIfTI datatype codes (nifti1.h) -> disk type; throws for non-scalar or exotic types.
DiskType disk_type_from(int datatype, const std::string& path) {
    switch (datatype) {
        case 2:
            return DiskType::U8;
        case 4:
            return DiskType::I16;
        case 8:
            return DiskType::I32;
        case 16:
            return DiskType::F32;
        case 64:
            return DiskType::F64;
        case 256:
            return DiskType::I8;
        case 512:
            return DiskType::U16;
        case 768:
            return DiskType::U32;
        case 1024:
            return DiskType::I64;
        case 1280:
            return DiskType::U64;
        case 128:
        case 2304:
            return DiskType::U8;  // RGB24 / RGBA32: bytes, read by read_rgb_stream
        case 32:
        case 1792:
        case 2048:
            throw Error(path, "datatype",
                        "complex voxels are not supported (NIfTI datatype " +
                            std::to_string(datatype) + ")");
        case 1536:
            throw Error(path, "datatype", "float128 voxels are not supported");
        default:
            throw Error(path, "datatype",
                        "unknown NIfTI datatype code " + std::to_string(datatype));
    }
}

// Colour channels of an RGB24 (3) or RGBA32 (4) file, 0 for a scalar one. Their bitpix must
// agree (24, 32): a file that says otherwise has been written wrong and its voxel size is
// unknowable. nifti1.h stores the channels interleaved per voxel (r, g, b[, a]) and says
// scl_slope/scl_inter do not apply to them.
int rgb_channels(const NiftiHeader& h, const std::string& path) {
    if (h.datatype != 128 && h.datatype != 2304) return 0;
    const int channels = h.datatype == 128 ? 3 : 4;
    if (h.bitpix != 8 * channels)
        throw Error(path, "bitpix",
                    "expected " + std::to_string(8 * channels) + " for " +
                        (channels == 3 ? "RGB24" : "RGBA32") + " (datatype " +
                        std::to_string(h.datatype) + "), got " + std::to_string(h.bitpix));
    return channels;
}

// The grid of one volume, and how many volumes the file holds along dim[4] (time, or any 4th
// axis: fMRI runs, diffusion directions, several echoes). Axes 5..7 must be 1: components (dim[5])
// are not volumes to choose from.
struct NiftiGrid {
    Vec3i dims;
    int64_t frames = 1;
};
NiftiGrid checked_dims(const NiftiHeader& h, const std::string& path) {
    const int64_t nd = h.dim[0];
    if (nd < 1 || nd > 7)
        throw Error(path, "header", "dim[0] is " + std::to_string(nd) + ", expected 1..7");
    if (nd < 3)
        throw Error(path, "dims", "expected a 3D volume, got a " + std::to_string(nd) + "D image");
    int64_t frames = 1;
    for (int i = 4; i <= nd; ++i) {
        if (h.dim[i] == 1) continue;
        if (i == 4 && h.dim[4] > 1 && h.dim[4] <= (int64_t(1) << 31)) {
            frames = h.dim[4];
            continue;
        }
        if (i == 5)
            throw Error(path, "dims",
                        "expected a scalar image, got " + std::to_string(h.dim[5]) + " components");
        throw Error(path, "dims",
                    "expected a 3D volume, got dim[" + std::to_string(i) + "] = " +
                        std::to_string(h.dim[i]) + " (a " + std::to_string(nd) + "D image)");
    }
    for (int a = 1; a <= 3; ++a) {
        if (h.dim[a] < 2 || h.dim[a] > kMaxDim)
            throw Error(path, "dims",
                        "expected 2.." + std::to_string(kMaxDim) + " voxels per axis, got " +
                            std::to_string(h.dim[1]) + "x" + std::to_string(h.dim[2]) + "x" +
                            std::to_string(h.dim[3]));
    }
    return {{int(h.dim[1]), int(h.dim[2]), int(h.dim[3])}, frames};
}

// The volume of a file with `frames` volumes that ReadOptions::frame names.
int64_t chosen_frame(int64_t frames, const std::optional<int64_t>& frame, const std::string& path) {
    const std::string range = "0.." + std::to_string(frames - 1);
    if (!frame) {
        if (frames == 1) return 0;
        throw Error(path, "frame",
                    "the file holds " + std::to_string(frames) +
                        " volumes along dim[4]; choose one (" + range + ")");
    }
    if (*frame < 0 || *frame >= frames)
        throw Error(path, "frame",
                    "expected " + range + (frames == 1 ? " (the file holds one volume)" : "") +
                        ", got " + std::to_string(*frame));
    return *frame;
}

double positive_or_one(double s) {
    return std::isfinite(s) && s > 0 ? s : 1.0;
}

// A NIfTI voxel-to-world affine (RAS+): world = m * (i, j, k) + t.
struct Affine {
    double m[3][3] = {};
    double t[3] = {};
    double column_norm(int c) const {
        return std::sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
    }
};

// The qform as a matrix (nifti1_io.c: nifti_quatern_to_mat44), scaled by pixdim.
Affine qform_affine(const NiftiHeader& h) {
    double b = h.quatern[0], c = h.quatern[1], d = h.quatern[2];
    double a = 1.0 - (b * b + c * c + d * d);
    if (a < 1e-7) {
        a = 1.0 / std::sqrt(b * b + c * c + d * d);
        b *= a;
        c *= a;
        d *= a;
        a = 0.0;
    } else {
        a = std::sqrt(a);
    }
    const double qfac = h.pixdim[0] < 0 ? -1.0 : 1.0;
    const double r[3][3] = {
        {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
        {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
        {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
    const double scale[3] = {positive_or_one(std::fabs(h.pixdim[1])),
                             positive_or_one(std::fabs(h.pixdim[2])),
                             qfac * positive_or_one(std::fabs(h.pixdim[3]))};
    Affine q;
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) q.m[row][col] = r[row][col] * scale[col];
        q.t[row] = h.qoffset[row];
    }
    return q;
}

Affine sform_affine(const NiftiHeader& h) {
    Affine s;
    for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) s.m[row][col] = h.srow[row][col];
        s.t[row] = h.srow[row][3];
    }
    return s;
}

bool finite_affine(const Affine& a) {
    for (int row = 0; row < 3; ++row) {
        if (!std::isfinite(a.t[row])) return false;
        for (int col = 0; col < 3; ++col)
            if (!std::isfinite(a.m[row][col])) return false;
    }
    return true;
}

// True when the 3x3 part is a rotation times per-axis scales (orthonormal once the columns are
// normalised): the only kind of matrix an origin + direction + spacing can represent.
bool is_rigid(const Affine& s) {
    if (!finite_affine(s)) return false;
    double n[3];
    for (int c = 0; c < 3; ++c) {
        n[c] = s.column_norm(c);
        if (!(n[c] > 0)) return false;
    }
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
            const double d = s.m[0][a] * s.m[0][b] + s.m[1][a] * s.m[1][b] + s.m[2][a] * s.m[2][b];
            if (std::fabs(d) > 1e-4 * n[a] * n[b]) return false;
        }
    return true;
}

bool similar(const Affine& a, const Affine& b, double tol) {
    for (int row = 0; row < 3; ++row) {
        if (std::fabs(a.t[row] - b.t[row]) > tol) return false;
        for (int col = 0; col < 3; ++col)
            if (std::fabs(a.m[row][col] - b.m[row][col]) > tol) return false;
    }
    return true;
}

double determinant(const Affine& a) {
    const auto& m = a.m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

std::string form_code_name(int code) {
    switch (code) {
        case 1:
            return "scanner";
        case 2:
            return "aligned";
        case 3:
            return "talairach";
        case 4:
            return "mni";
        case 5:
            return "template";
        default:
            return "unknown";
    }
}

// Sets spacing, origin and direction (LPS+) from the header, choosing between qform and sform
// the way ITK's NiftiImageIO does, so a file reads the same here as in ITK-based tools:
//   neither code set                       -> pixdim only: RAS-aligned, origin 0 (as nibabel and
//                                             niftilib's method 1; world = index * spacing)
//   sform rigid and (qform unknown, or sform_code SCANNER_ANAT, or sform ~= qform) -> sform
//   otherwise, qform code set              -> qform
//   otherwise (only a sheared sform)       -> refused: lacuna does not render sheared grids
// Spacing always comes from pixdim, as in ITK. A transform whose code is set but whose numbers
// are unusable (NaN quaternion or offset, non-finite, zero or singular sform) is an error naming
// the field, not silently replaced by another transform. Records the choice in geometry_source.
void set_geometry(const NiftiHeader& h, Volume& v, const std::string& path) {
    v.spacing = {positive_or_one(std::fabs(h.pixdim[1])), positive_or_one(std::fabs(h.pixdim[2])),
                 positive_or_one(std::fabs(h.pixdim[3]))};
    auto nums = [](const double* x, int n) {
        std::string t;
        for (int i = 0; i < n; ++i) t += (i ? " " : "") + std::to_string(x[i]);
        return t;
    };
    const bool have_q = h.qform_code > 0;
    const bool have_s = h.sform_code > 0;
    if (have_q) {
        if (!std::isfinite(h.quatern[0] + h.quatern[1] + h.quatern[2]))
            throw Error(path, "quatern_b/c/d",
                        "qform_code is " + std::to_string(h.qform_code) +
                            " but the quaternion is not finite: " + nums(h.quatern, 3));
        if (!std::isfinite(h.qoffset[0] + h.qoffset[1] + h.qoffset[2]))
            throw Error(path, "qoffset_x/y/z",
                        "qform_code is " + std::to_string(h.qform_code) +
                            " but the offset is not finite: " + nums(h.qoffset, 3));
        if (!std::isfinite(h.pixdim[0]))
            throw Error(path, "pixdim[0]", "the qform's qfac is not finite");
    }
    const Affine s = sform_affine(h);
    if (have_s) {
        static const char* rows[3] = {"srow_x", "srow_y", "srow_z"};
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(s.t[r] + s.m[r][0] + s.m[r][1] + s.m[r][2]))
                throw Error(path, rows[r],
                            "sform_code is " + std::to_string(h.sform_code) +
                                " but the row is not finite: " + nums(h.srow[r], 4));
        const double scale = s.column_norm(0) * s.column_norm(1) * s.column_norm(2);
        if (!(std::fabs(determinant(s)) > 1e-12 * scale) || !(scale > 0))
            throw Error(path, "srow_x/y/z",
                        "sform_code is " + std::to_string(h.sform_code) +
                            " but the sform is singular (a zero axis or axes in one plane): [" +
                            nums(h.srow[0], 4) + "] [" + nums(h.srow[1], 4) + "] [" +
                            nums(h.srow[2], 4) + "]");
    }
    if (!have_q && !have_s) {
        v.origin = {0, 0, 0};
        const double ras_identity_in_lps[9] = {-1, 0, 0, 0, -1, 0, 0, 0, 1};
        for (int i = 0; i < 9; ++i) v.direction[i] = ras_identity_in_lps[i] + 0.0;
        v.geometry_source = "NIfTI pixdim only (qform_code and sform_code 0)";
        return;
    }
    const Affine q = have_q ? qform_affine(h) : Affine{};
    bool use_s = false;
    if (have_s && is_rigid(s)) {
        constexpr int kScannerAnat = 1;
        use_s = !have_q || h.sform_code == kScannerAnat || similar(q, s, 1e-4);
    }
    if (have_s && !use_s && !have_q)
        throw Error(path, "srow_x/y/z",
                    "the sform is sheared (its axes are not perpendicular) and there is no qform "
                    "to fall back on; lacuna does not render sheared grids");
    const Affine& m = use_s ? s : q;
    v.geometry_source = use_s ? "NIfTI sform (sform_code " + std::to_string(h.sform_code) + ", " +
                                    form_code_name(h.sform_code) + ")"
                              : "NIfTI qform (qform_code " + std::to_string(h.qform_code) + ", " +
                                    form_code_name(h.qform_code) + ")" +
                                    (have_s ? std::string(is_rigid(s) ? ", the sform differs"
                                                                      : ", the sform is sheared")
                                            : "");
    // RAS+ -> LPS+: flip the first two world axes. "+ 0.0" turns -0 into 0 for printouts.
    const double flip[3] = {-1.0, -1.0, 1.0};
    for (int col = 0; col < 3; ++col) {
        const double n = m.column_norm(col);
        for (int row = 0; row < 3; ++row)
            v.direction[row * 3 + col] = (n > 0 ? flip[row] * m.m[row][col] / n : 0.0) + 0.0;
    }
    for (int row = 0; row < 3; ++row) v.origin[row] = flip[row] * m.t[row] + 0.0;
}

}  // namespace

namespace {

// The files of a NIfTI volume: one .nii / .nii.gz, or a pair, named by either of its files:
// name.hdr (or .hdr.gz) for the header and name.img (or .img.gz) for the voxels.
struct NiftiFiles {
    std::string header, data;
    bool pair = false;
};
NiftiFiles nifti_files(const std::string& path) {
    const std::string ext = format_extension(path);
    if (ext != ".hdr" && ext != ".img" && ext != ".img.gz" && ext != ".hdr.gz")
        return {path, path, false};
    const std::string stem = path.substr(0, path.size() - ext.size());
    auto first = [&](std::initializer_list<const char*> exts) {
        for (const char* e : exts)
            if (std::filesystem::exists(stem + e)) return stem + e;
        return stem + *exts.begin();
    };
    NiftiFiles f;
    f.pair = true;
    f.header = ext == ".hdr" || ext == ".hdr.gz" ? path : first({".hdr", ".hdr.gz"});
    f.data = ext == ".img" || ext == ".img.gz" ? path : first({".img", ".img.gz"});
    check_readable_file(f.header);
    check_readable_file(f.data);
    return f;
}

}  // namespace

Volume read_nifti(const std::string& path, const ReadOptions& opts, RgbOpacity rgb_opacity,
                  VoxelLayout* header_only) {
    const NiftiFiles files = nifti_files(path);
    GzFile hf(gzopen(files.header.c_str(), "rb"));
    if (!hf) throw Error(files.header, "file", std::string("cannot open: ") + std::strerror(errno));
    gzbuffer(hf.get(), 1u << 20);
    const NiftiHeader h = parse_header(hf.get(), files.header, files.pair);
    // The voxels: after the header in the same stream, or in the pair's .img.
    GzFile df(files.pair ? gzopen(files.data.c_str(), "rb") : nullptr);
    if (files.pair && !df)
        throw Error(files.data, "file", std::string("cannot open: ") + std::strerror(errno));
    if (files.pair) gzbuffer(df.get(), 1u << 20);
    gzFile f = files.pair ? df.get() : hf.get();
    const std::string& data_path = files.data;
    const NiftiGrid grid = checked_dims(h, path);
    const Vec3i dims = grid.dims;
    const int64_t frame = chosen_frame(grid.frames, opts.frame, path);
    const DiskType disk = disk_type_from(h.datatype, path);
    const int channels = rgb_channels(h, path);  // 0: a scalar file
    if (channels) check_rgb_opacity(channels, rgb_opacity, path);

    // NIfTI: slope 0 (or non-finite) means "no scaling"; scaled data is float, as in ITK.
    const bool rescale = !channels && std::isfinite(h.slope) && std::isfinite(h.inter) &&
                         h.slope != 0.0 && (h.slope != 1.0 || h.inter != 0.0);
    const VoxelType type = channels  ? rgb_scalar_type(rgb_opacity)
                           : rescale ? VoxelType::Float32
                                     : stored_type(disk);
    // dims are 2..kMaxDim each, so these products fit; sat_add guards a wild vox_offset. The
    // chosen volume starts `frame` volumes after vox_offset (frames are stored one after another).
    const uint64_t data_bytes = grid_bytes(dims, channels ? channels : disk_type_size(disk));
    const uint64_t offset = sat_add(uint64_t(h.vox_offset), sat_mul(uint64_t(frame), data_bytes));
    if (channels && header_only)
        throw Error(path, "datatype",
                    "RGB volumes are read whole, not by brick (distributed frames)");
    if (!header_only)
        check_budget(
            path, "dims",
            dims_string(dims) + " " +
                (channels ? std::string(channels == 3 ? "RGB24" : "RGBA32") : to_string(type)),
            grid_bytes(dims, channels ? rgb_bytes_per_voxel(rgb_opacity) : voxel_size(type)),
            opts.max_memory);

    // An uncompressed file's length is known: report truncation before allocating. A
    // compressed one is inflated incrementally into the buffer, whose pages are only touched
    // as data arrives (Volume's constructor), so a short stream fails as fast as it ends.
    if (gzdirect(f)) {
        std::error_code ec;
        const auto file_bytes = std::filesystem::file_size(data_path, ec);
        if (!ec && file_bytes < sat_add(offset, data_bytes))
            throw Error(data_path, "voxel data",
                        "truncated: expected " + std::to_string(data_bytes) +
                            " bytes of voxels after offset " + std::to_string(offset) +
                            (frame ? " (volume " + std::to_string(frame) + ")" : std::string()) +
                            ", the file has " +
                            std::to_string(file_bytes > offset ? file_bytes - offset : 0));
    }

    Volume v = header_only ? Volume(dims, type, nullptr, nullptr)
               : channels  ? rgb_volume(dims, channels, rgb_opacity, path)
                           : Volume(dims, type, path);
    set_geometry(h, v, path);
    check_geometry(v, path);  // before the voxels are read
    if (header_only) {
        *header_only = {data_path,        offset,  disk,    h.swap,
                        gzdirect(f) != 0, rescale, h.slope, h.inter};
        return v;
    }
    // (a compressed file is inflated up to the offset; gzseek says -1 if the stream ends first)
    if (offset > uint64_t(std::numeric_limits<z_off_t>::max()) ||
        gzseek(f, z_off_t(offset), SEEK_SET) != z_off_t(offset))
        throw Error(
            data_path, "voxel data",
            frame ? "truncated: the file ends before volume " + std::to_string(frame) +
                        " at offset " + std::to_string(offset)
                  : "truncated: the file ends before vox_offset " + std::to_string(h.vox_offset));
    const auto read = [&](void* buf, size_t n) { return gz_read_all(f, buf, n, data_path); };
    if (channels)  // bytes: no byte order to swap
        read_rgb_stream(read, v, data_path, opts.progress);
    else
        read_voxel_stream(read, disk, h.swap, v, data_path, opts.progress, rescale, h.slope,
                          h.inter);
    return v;
}

int64_t nifti_frames(const std::string& path) {
    const NiftiFiles files = nifti_files(path);
    GzFile hf(gzopen(files.header.c_str(), "rb"));
    if (!hf) throw Error(files.header, "file", std::string("cannot open: ") + std::strerror(errno));
    return checked_dims(parse_header(hf.get(), files.header, files.pair), path).frames;
}

}  // namespace lacuna::io
