// Patient orientation end to end (issue 14): the same anatomy stored in other voxel orders and
// conventions (axis permutations, flips, LPS vs RAS, NIfTI sform-only and qform-only, NRRD,
// MetaImage, a DICOM series) reads to the same world and renders to the same picture; a 30-degree
// oblique sform turns the picture by 30 degrees; every structure and kernel path stays exact on
// oblique data; the named views put the anatomy where a radiologist expects it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "../conformance/conformance_util.h"
#include "../io/io_test_util.h"
#include "../io/nifti_test_file.h"
#include "core/simd_lanes.h"
#include "lacuna/accel.h"
#include "lacuna/camera.h"
#include "lacuna/frame_spec.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"
#include "lacuna/renderer.h"
#include "lacuna/session.h"
#include "lacuna/transfer_function.h"
#include "orientation_test_util.h"

namespace lacuna {
namespace {

using namespace test::orientation;

RenderResult render(const Volume& v, const Camera& cam, const TransferLut& lut,
                    const Accel* accel = nullptr, RenderOptions o = {}) {
    RayMarcher m(v);
    m.set_transfer_function(lut);
    m.set_accel(accel);
    return m.render(cam, o);
}

Camera orbit(const Box3f& bounds, float az, float el, Projection p, int size) {
    OrbitParams op;
    op.azimuth_deg = az;
    op.elevation_deg = el;
    op.projection = p;
    return Camera::orbit(bounds, op, size, size);
}

// The proper-rotation quaternion (b, c, d) and qfac of a RAS direction (nifti1_io.c's
// nifti_mat44_to_quatern), for qform-only files.
void quaternion(Mat3 r, std::array<double, 3>& bcd, double& qfac) {
    const double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                       r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                       r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    qfac = det < 0 ? -1 : 1;
    if (det < 0)
        for (int row = 0; row < 3; ++row) r[row][2] = -r[row][2];
    double a = r[0][0] + r[1][1] + r[2][2] + 1, b, c, d;
    if (a > 0.5) {
        a = 0.5 * std::sqrt(a);
        b = 0.25 * (r[2][1] - r[1][2]) / a;
        c = 0.25 * (r[0][2] - r[2][0]) / a;
        d = 0.25 * (r[1][0] - r[0][1]) / a;
    } else {
        const double xd = 1 + r[0][0] - (r[1][1] + r[2][2]), yd = 1 + r[1][1] - (r[0][0] + r[2][2]),
                     zd = 1 + r[2][2] - (r[0][0] + r[1][1]);
        if (xd > 1) {
            b = 0.5 * std::sqrt(xd);
            c = 0.25 * (r[0][1] + r[1][0]) / b;
            d = 0.25 * (r[0][2] + r[2][0]) / b;
            a = 0.25 * (r[2][1] - r[1][2]) / b;
        } else if (yd > 1) {
            c = 0.5 * std::sqrt(yd);
            b = 0.25 * (r[0][1] + r[1][0]) / c;
            d = 0.25 * (r[1][2] + r[2][1]) / c;
            a = 0.25 * (r[0][2] - r[2][0]) / c;
        } else {
            d = 0.5 * std::sqrt(zd);
            b = 0.25 * (r[0][2] + r[2][0]) / d;
            c = 0.25 * (r[1][2] + r[2][1]) / d;
            a = 0.25 * (r[1][0] - r[0][1]) / d;
        }
        if (a < 0) b = -b, c = -c, d = -d;
    }
    bcd = {b, c, d};
}

enum class NiftiForm { SformOnly, QformOnly };
// A uint8 volume as a NIfTI file with only one of its two transforms set.
void write_nifti(const std::string& path, const Volume& v, NiftiForm form, int version) {
    test::NiftiSpec s;
    s.version = version;
    s.dims = v.dims();
    s.datatype = 2;
    s.pixdim = v.spacing;
    const Affine a = index_to_world(v);
    if (form == NiftiForm::SformOnly) {
        s.sform_code = 2;
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) s.srow[size_t(r)][size_t(c)] = a.m[r][c];
            s.srow[size_t(r)][3] = a.t[r];
        }
    } else {
        s.qform_code = 1;
        quaternion(ras_direction(v), s.quatern, s.qfac);
        s.qoffset = {a.t[0], a.t[1], a.t[2]};
    }
    const std::vector<uint8_t> bytes = test::nifti_bytes(s, v.data(), v.bytes());
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

struct Variant {
    const char* name;
    std::array<int, 3> perm;
    std::array<bool, 3> flip;
    const char* code;  // expected orientation code
    const char* file;  // written as
    enum { Itk, Sform, Qform2, Dicom } how;
};

// Seven storages of one anatomy (the first is the reference's own order).
const Variant kVariants[] = {
    {"RAS NIfTI (ITK writer: sform + qform)",
     {0, 1, 2},
     {false, false, false},
     "RAS",
     "ras.nii.gz",
     Variant::Itk},
    {"LPS NRRD", {0, 1, 2}, {true, true, false}, "LPS", "lps.nrrd", Variant::Itk},
    {"sagittal PIR MetaImage", {1, 2, 0}, {true, true, false}, "PIR", "pir.mha", Variant::Itk},
    {"permuted SRA detached NRRD",
     {2, 0, 1},
     {false, false, false},
     "SRA",
     "sra.nhdr",
     Variant::Itk},
    {"LPI NIfTI-2 qform only (qfac -1)",
     {0, 1, 2},
     {true, true, true},
     "LPI",
     "lpi.nii",
     Variant::Qform2},
    {"coronal LIA NIfTI-1 sform only",
     {0, 2, 1},
     {true, true, false},
     "LIA",
     "lia.nii",
     Variant::Sform},
    {"axial LPS DICOM series (IOP 1\\0\\0\\0\\1\\0)",
     {0, 1, 2},
     {true, true, false},
     "LPS",
     "dicom/",
     Variant::Dicom},
};

Volume write_and_read(const Volume& v, const Variant& var, const test::ScratchDir& dir) {
    const std::string path = dir.file(var.file);
    switch (var.how) {
        case Variant::Sform:
            write_nifti(path, v, NiftiForm::SformOnly, 1);
            break;
        case Variant::Qform2:
            write_nifti(path, v, NiftiForm::QformOnly, 2);
            break;
        default:
            write_volume(path, v);
    }
    return read_volume(path);
}

void expect_same_world(const Volume& got, const Volume& want, const std::string& what) {
    const Box3f a = world_bounds(got), b = world_bounds(want);
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(a.lo[i], b.lo[i], 1e-3) << what;
        EXPECT_NEAR(a.hi[i], b.hi[i], 1e-3) << what;
    }
}

TEST(Orientation, EveryVoxelOrderAndFormatOfThePhantomRendersTheSamePicture) {
    const Volume base = phantom();
    const TransferLut lut = phantom_lut();
    const Box3f bounds = world_bounds(base);
    const Camera cams[] = {orbit(bounds, 30, 20, Projection::Perspective, 96),
                           orbit(bounds, 250, -35, Projection::Orthographic, 96)};
    const test::ScratchDir dir;
    for (const Variant& var : kVariants) {
        const Volume stored = reorder(base, var.perm, var.flip);
        const Volume v = write_and_read(stored, var, dir);
        SCOPED_TRACE(var.name);
        EXPECT_EQ(orientation_code(v), var.code);
        EXPECT_EQ(v.dims(), stored.dims());
        expect_same_world(v, base, var.name);
        // The voxel order changed, the anatomy did not: the voxel at world w holds the same value.
        const Affine a = index_to_world(v), ab = index_to_world(base);
        for (Vec3d idx : {Vec3d{3, 5, 7}, Vec3d{20, 24, 18}, Vec3d{35, 10, 30}}) {
            const Vec3d w = ab.apply(idx);
            Vec3d q{};  // the same point in v's index space (a signed permutation: solve per axis)
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r)
                    if (std::fabs(a.m[r][c]) > 0.5 * v.spacing[c])
                        q[c] = (w[r] - a.t[r]) / a.m[r][c];
            EXPECT_EQ(v.value(int(std::lround(q.x)), int(std::lround(q.y)), int(std::lround(q.z))),
                      base.value(int(idx.x), int(idx.y), int(idx.z)));
        }
        const bool same_order = var.perm == std::array<int, 3>{0, 1, 2} &&
                                var.flip == std::array<bool, 3>{false, false, false};
        for (const Camera& cam : cams)
            expect_same_picture(render(v, cam, lut).image, render(base, cam, lut).image, var.name,
                                same_order);
        // World options are world options whatever the storage: a clip plane, a crop box, a
        // directional light with Phong shading, a spotlight with shadows (all in RAS mm).
        RenderOptions f;
        f.features.shading = ShadingModel::Phong;
        f.features.light.kind = LightKind::Directional;
        f.features.light.direction = {1, 0.5f, 0.2f};
        f.features.clip_planes.push_back({{-1, 0, 0}, -6.f});  // keep x <= 6 mm
        f.features.crop = true;
        f.features.crop_box = {{-30, -12, -30}, {30, 30, 12}};
        RenderOptions spot;
        spot.features.shading = ShadingModel::Pbr;
        spot.features.light.kind = LightKind::Spot;
        spot.features.light.position = {40, 50, 40};
        spot.features.light.target = {0, 0, 0};
        spot.features.shadows.enabled = true;
        for (const RenderOptions& o : {f, spot})
            expect_same_picture(render(v, cams[0], lut, nullptr, o).image,
                                render(base, cams[0], lut, nullptr, o).image,
                                std::string(var.name) + " with world features", same_order);
    }
}

// The real head: ch2 as shipped (RAS), and re-stored in six other voxel orders and conventions
// (LPS NRRD, sagittal PIR MetaImage, permuted SRA detached NRRD, LPI NIfTI-2 qform only, coronal
// LIA NIfTI-1 sform only, an axial LPS DICOM series).
TEST(Orientation, TheCh2HeadRendersTheSameInEveryStorage) {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    if (!std::filesystem::exists(ch2)) GTEST_SKIP() << ch2 << " (Debian mricron-data) is missing";
    const Volume base = read_volume(ch2);
    EXPECT_EQ(orientation_code(base), "RAS");
    const TransferLut lut = discretise(preset("mr-skin"), base.vis_range());
    const Box3f bounds = world_bounds(base);
    const Camera cam = orbit(bounds, 30, 15, Projection::Perspective, 80);
    const RenderResult want = render(base, cam, lut);
    const test::ScratchDir dir;
    for (const Variant& var :
         {kVariants[1], kVariants[2], kVariants[3], kVariants[4], kVariants[5], kVariants[6]}) {
        const Volume v = write_and_read(reorder(base, var.perm, var.flip), var, dir);
        SCOPED_TRACE(var.name);
        EXPECT_EQ(orientation_code(v), var.code);
        expect_same_world(v, base, var.name);
        expect_same_picture(render(v, cam, lut).image, want.image, std::string("ch2 ") + var.name,
                            false);
    }
}

// Maximum-intensity projection: each marker shows in its own colour wherever it projects (in
// a composite picture the blue rim of the 220-marker would hide its red core). The marker LUT is
// opaque only in narrow bands around the markers' plateau values, so the rim of one marker,
// whose maximum runs through every lower value, never passes for another marker.
RenderOptions mip() {
    RenderOptions o;
    o.features.blend = BlendMode::Mip;
    return o;
}
TransferLut marker_lut() {
    TransferFunction tf;
    tf.name = "markers";
    tf.domain = TfDomain::Value;
    tf.color = {{0, 0.1f, 0.2f, 1.0f},   {130, 0.1f, 0.2f, 1.0f}, {130, 0.1f, 1.0f, 0.2f},
                {190, 0.1f, 1.0f, 0.2f}, {190, 1.0f, 0.1f, 0.1f}, {255, 1.0f, 0.1f, 0.1f}};
    tf.opacity = {{0, 0},   {97, 0},  {97, 1},  {103, 1}, {103, 0}, {157, 0},
                  {157, 1}, {163, 1}, {163, 0}, {217, 0}, {217, 1}, {255, 1}};
    return discretise(tf, {0, 255});
}

// Centroid of the pixels whose dominant channel is `c` (0 red, 1 green, 2 blue), in pixels.
bool centroid(const Image& im, int c, double& x, double& y) {
    double sx = 0, sy = 0, n = 0;
    for (int py = 0; py < im.height; ++py)
        for (int px = 0; px < im.width; ++px) {
            const uint8_t* p = &im.rgba[(size_t(py) * size_t(im.width) + size_t(px)) * 4];
            if (p[c] > 60 && p[c] > 2 * p[(c + 1) % 3] && p[c] > 2 * p[(c + 2) % 3]) {
                sx += px, sy += py, n += 1;
            }
        }
    if (n < 4) return false;
    x = sx / n;
    y = sy / n;
    return true;
}

TEST(Orientation, NamedViewsPutTheAnatomyWhereRadiologistsExpectIt) {
    const Volume v = phantom();
    const TransferLut lut = marker_lut();
    const Box3f b = world_bounds(v);
    double x, y;
    // Anterior view (azimuth 0): the patient faces us, their right is on the screen's left,
    // superior is up.
    const Image front =
        render(v, orbit(b, 0, 0, Projection::Orthographic, 96), lut, nullptr, mip()).image;
    ASSERT_TRUE(centroid(front, 0, x, y));  // right marker
    EXPECT_LT(x, 43);
    ASSERT_TRUE(centroid(front, 2, x, y));  // superior marker
    EXPECT_LT(y, 43);
    // Left view (azimuth 90): the face (anterior marker) is on the screen's left.
    const Image left =
        render(v, orbit(b, 90, 0, Projection::Orthographic, 96), lut, nullptr, mip()).image;
    ASSERT_TRUE(centroid(left, 1, x, y));
    EXPECT_LT(x, 43);
    // Posterior view: the patient's right is on the screen's right.
    const Image back =
        render(v, orbit(b, 180, 0, Projection::Orthographic, 96), lut, nullptr, mip()).image;
    ASSERT_TRUE(centroid(back, 0, x, y));
    EXPECT_GT(x, 53);
    // Superior view (looking down, anterior up): the face marker is at the top, right is right.
    const Image top =
        render(v, orbit(b, 0, 90, Projection::Orthographic, 96), lut, nullptr, mip()).image;
    ASSERT_TRUE(centroid(top, 1, x, y));
    EXPECT_LT(y, 43);
    ASSERT_TRUE(centroid(top, 0, x, y));
    EXPECT_GT(x, 53);
    // The default view (azimuth 30, elevation 15: render's and the viewer's) is from the
    // front-left and upright: the face (anterior marker) is left of centre, as in the left view,
    // the top marker above the centre, and the right marker, seen past the face, left too.
    const Image deflt =
        render(v, orbit(b, 30, 15, Projection::Orthographic, 96), lut, nullptr, mip()).image;
    ASSERT_TRUE(centroid(deflt, 1, x, y));
    EXPECT_LT(x, 43);
    ASSERT_TRUE(centroid(deflt, 2, x, y));
    EXPECT_LT(y, 43);
    ASSERT_TRUE(centroid(deflt, 0, x, y));
    EXPECT_LT(x, 47.5);
}

// The phantom with its sform turned 30 degrees about the superior axis (about its centre):
// seen from above, the markers turn by 30 degrees counter-clockwise.
Volume rotated(const Volume& base, double degrees) {
    Volume v = base;
    const double a = degrees * M_PI / 180, c = std::cos(a), s = std::sin(a);
    const Mat3 rz{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
    const Affine ab = index_to_world(base);
    const Vec3i d = base.dims();
    const Vec3d centre = ab.apply({0.5 * (d.x - 1), 0.5 * (d.y - 1), 0.5 * (d.z - 1)});
    Mat3 r{};
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col)
            for (int k = 0; k < 3; ++k)
                r[row][col] += rz[row][k] * (ab.m[k][col] / base.spacing[col]);
    set_ras_direction(v, r);
    // Keep the centre: t = centre - R S ic.
    Vec3d t = centre;
    const double ic[3] = {0.5 * (d.x - 1), 0.5 * (d.y - 1), 0.5 * (d.z - 1)};
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) t[row] -= r[row][col] * base.spacing[col] * ic[col];
    set_ras_origin(v, t);
    return v;
}

TEST(Orientation, AThirtyDegreeObliqueSformTurnsThePictureByThirtyDegrees) {
    const Volume base = phantom();
    const test::ScratchDir dir;
    // Through a file: the oblique sform is what the reader must honour.
    const std::string path = dir.file("oblique.nii");
    write_nifti(path, rotated(base, 30), NiftiForm::SformOnly, 1);
    const Volume v = read_volume(path);
    EXPECT_NE(v.geometry_source.find("sform"), std::string::npos) << v.geometry_source;
    const TransferLut lut = marker_lut();
    // One camera for both: framed on the unrotated box, looking down from superior.
    const Camera cam = orbit(world_bounds(base), 0, 90, Projection::Orthographic, 192);
    const Image a = render(base, cam, lut, nullptr, mip()).image,
                b = render(v, cam, lut, nullptr, mip()).image;
    const double cx = 95.5, cy = 95.5;
    for (int marker : {0, 1}) {  // the right marker and the anterior marker
        double x0, y0, x1, y1;
        ASSERT_TRUE(centroid(a, marker, x0, y0));
        ASSERT_TRUE(centroid(b, marker, x1, y1));
        // Screen y grows downward; angles counter-clockwise with y up.
        const double t0 = std::atan2(-(y0 - cy), x0 - cx), t1 = std::atan2(-(y1 - cy), x1 - cx);
        double turn = (t1 - t0) * 180 / M_PI;
        if (turn > 180) turn -= 360;
        if (turn < -180) turn += 360;
        EXPECT_NEAR(turn, 30.0, 2.0)
            << "marker " << marker << " " << x0 << "," << y0 << " -> " << x1 << "," << y1;
        // The distance from the centre is kept (a rotation, not a scale).
        EXPECT_NEAR(std::hypot(x1 - cx, y1 - cy), std::hypot(x0 - cx, y0 - cy), 1.5);
    }
}

// Oblique and mirrored volumes: every structure on every kernel path gives the scalar --accel
// none bytes and float sums (the lattice and the structures never left index space).
TEST(Orientation, EveryStructureAndKernelPathIsExactOnObliqueData) {
    const test::KernelPaths kp;
    test::Rng rng{14};
    int compared = 0;
    for (int trial = 0; trial < 6; ++trial) {
        Volume v = trial < 2 ? phantom() : test::random_volume(rng, 29);
        v.spacing = {0.6 + rng.uniform(), 0.6 + rng.uniform(), 0.6 + rng.uniform()};
        // A random rotation (three angles), mirrored on odd trials, and a random origin.
        const double ax = 6.3 * rng.uniform(), ay = 6.3 * rng.uniform(), az = 6.3 * rng.uniform();
        const Mat3 rx{
            {{1, 0, 0}, {0, std::cos(ax), -std::sin(ax)}, {0, std::sin(ax), std::cos(ax)}}};
        const Mat3 ry{
            {{std::cos(ay), 0, std::sin(ay)}, {0, 1, 0}, {-std::sin(ay), 0, std::cos(ay)}}};
        const Mat3 rz{
            {{std::cos(az), -std::sin(az), 0}, {std::sin(az), std::cos(az), 0}, {0, 0, 1}}};
        auto mul = [](const Mat3& p, const Mat3& q) {
            Mat3 o{};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    for (int k = 0; k < 3; ++k) o[i][j] += p[i][k] * q[k][j];
            return o;
        };
        Mat3 r = mul(rz, mul(ry, rx));
        if (trial % 2)
            for (int row = 0; row < 3; ++row) r[row][1] = -r[row][1];
        set_ras_direction(v, r);
        set_ras_origin(
            v, {100 * rng.uniform() - 50, 100 * rng.uniform() - 50, 100 * rng.uniform() - 50});
        ASSERT_NO_THROW(check_geometry(v, "oblique"));
        const TransferLut lut = trial < 2 ? phantom_lut() : test::random_lut(v.vis_range(), rng);
        const Box3f b = world_bounds(v);
        const Camera cam =
            orbit(b, 360.f * rng.uniform(), -70.f + 140.f * rng.uniform(),
                  trial % 3 ? Projection::Perspective : Projection::Orthographic, 31);
        RenderOptions o;
        o.keep_float = true;
        o.count_samples = true;
        o.ert = trial % 2 ? 0.9f : 2.f;
        simd::set_isa(simd::Isa::Scalar);
        const RenderResult ref = render(v, cam, lut, nullptr, o);
        uint64_t visible = 0;
        for (size_t p = 0; p < ref.image.rgba.size(); p += 4) visible += ref.image.rgba[p + 3] != 0;
        if (trial < 2) EXPECT_GT(visible, 50u) << "the phantom is in view";
        for (AccelKind k : all_accel_kinds()) {
            auto accel = make_accel(k, v);
            accel->set_transfer_function(lut);
            for (simd::Isa isa : kp.paths) {
                simd::set_isa(isa);
                const RenderResult got = render(v, cam, lut, accel.get(), o);
                const std::string what = "trial " + std::to_string(trial) + " accel " +
                                         to_string(k) + " path " + simd::to_string(isa);
                ASSERT_EQ(got.image.rgba, ref.image.rgba) << what;
                ASSERT_EQ(0, std::memcmp(got.rgba_float.data(), ref.rgba_float.data(),
                                         ref.rgba_float.size() * sizeof(float)))
                    << what;
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 40);
}

// "Every structure stays exact on oblique data", for every renderer and not only the marcher:
// through the session, each structure on each renderer the capabilities table grants it (the
// slicer's kd-tree and growing boxes, the segment renderer's label octree and its mask mode over
// the intensity structures, the marcher's) gives that renderer's image without skipping byte for
// byte, on the phantom turned 30 degrees and on a copy rotated about all three axes and mirrored,
// with a label map in the same (oblique) frame.
TEST(Orientation, EveryStructureOnEveryRendererIsExactOnObliqueData) {
    Volume mirrored = phantom();
    {
        const double a = 0.7, b = 0.4;  // about x, then about z; then j reversed
        const Mat3 rx{{{1, 0, 0}, {0, std::cos(a), -std::sin(a)}, {0, std::sin(a), std::cos(a)}}};
        const Mat3 rz{{{std::cos(b), -std::sin(b), 0}, {std::sin(b), std::cos(b), 0}, {0, 0, 1}}};
        Mat3 r{};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int k = 0; k < 3; ++k) r[i][j] += rz[i][k] * rx[k][j];
        for (int row = 0; row < 3; ++row) r[row][1] = -r[row][1];
        set_ras_direction(mirrored, r);
        set_ras_origin(mirrored, {12, -40, 7});
    }
    int compared = 0;
    for (const Volume& v : {rotated(phantom(), 30), mirrored}) {
        ASSERT_NO_THROW(check_geometry(v, "oblique"));
        // Labels: the body 1, each marker its own label, in the volume's own frame.
        Volume labels(v.dims(), VoxelType::UInt8);
        labels.spacing = v.spacing;
        labels.origin = v.origin;
        std::copy(std::begin(v.direction), std::end(v.direction), labels.direction);
        for (int k = 0; k < v.dims().z; ++k)
            for (int j = 0; j < v.dims().y; ++j)
                for (int i = 0; i < v.dims().x; ++i) {
                    const float x = v.value(i, j, k);
                    labels.set_value(i, j, k,
                                     x > 200   ? 4.f
                                     : x > 140 ? 3.f
                                     : x > 90  ? 2.f
                                     : x > 20  ? 1.f
                                               : 0.f);
                }
        labels.compute_range();
        Session session(v, 1);
        session.set_labels(std::move(labels));
        session.set_transfer_function(phantom_tf());
        for (const RendererCapabilities& cap : capabilities()) {
            FrameSpec none;
            none.renderer = cap.renderer;
            none.structure = structure::None{};
            none.width = 56;
            none.height = 48;
            none.camera.orbit.azimuth_deg = 35.f;
            none.camera.orbit.elevation_deg = 20.f;
            const FrameResult reference = session.render(none);
            size_t lit = 0;
            for (size_t p = 0; p < reference.image.rgba.size(); p += 4)
                lit += reference.image.rgba[p] + reference.image.rgba[p + 1] +
                           reference.image.rgba[p + 2] >
                       0;
            EXPECT_GT(lit, 80u) << to_string(cap.renderer) << ": the markers are in view";
            for (const Structure& st : all_structures()) {
                if (!cap.takes(st)) continue;
                FrameSpec f = none;
                f.structure = st;
                const FrameResult r = session.render(f);
                EXPECT_TRUE(r.image.rgba == reference.image.rgba)
                    << to_string(cap.renderer) << " " << structure_name(st);
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 20);
}

// Features in world coordinates on an oblique volume: a clip plane, a crop box (which becomes
// six planes in the volume frame), shading with a directional light; every structure exact.
TEST(Orientation, WorldClipPlanesCropBoxAndLightsStayExactOnObliqueData) {
    Volume v = rotated(phantom(), 30);
    const TransferLut lut = phantom_lut();
    const Box3f b = world_bounds(v);
    const Camera cam = orbit(b, 40, 25, Projection::Perspective, 40);
    RenderOptions o;
    o.keep_float = true;
    o.features.shading = ShadingModel::Phong;
    o.features.light.kind = LightKind::Directional;
    o.features.light.direction = {1, 1, 1};
    o.features.clip_planes.push_back({{0, 0, -1}, -8.f});  // keep z <= 8 mm (RAS)
    o.features.crop = true;
    o.features.crop_box = {{-30, -30, -30}, {8, 30, 30}};  // cut the right marker in half
    // The scalar --accel none picture is the reference for every structure on every kernel path
    // (the shaded SIMD path sets its rays up from the same volume-frame camera).
    const test::KernelPaths kp;
    simd::set_isa(simd::Isa::Scalar);
    const RenderResult ref = render(v, cam, lut, nullptr, o);
    for (AccelKind k : all_accel_kinds()) {
        auto accel = make_accel(k, v);
        accel->set_transfer_function(lut);
        for (simd::Isa isa : kp.paths) {
            simd::set_isa(isa);
            const RenderResult got = render(v, cam, lut, accel.get(), o);
            ASSERT_EQ(got.image.rgba, ref.image.rgba)
                << to_string(k) << " " << simd::to_string(isa);
        }
    }
    simd::set_isa(kp.saved);
    // The crop removes what lies beyond x = 8 mm: the same as a plane there.
    RenderOptions planes = o;
    planes.features.crop = false;
    planes.features.clip_planes.push_back({{-1, 0, 0}, -8.f});
    const Diff d = compare(render(v, cam, lut, nullptr, planes).image, ref.image);
    EXPECT_GE(double(d.within_one), 0.999 * double(d.pixels)) << "max " << d.max;
    // And it removes something: the uncropped picture differs.
    RenderOptions uncropped = o;
    uncropped.features.crop = false;
    EXPECT_NE(render(v, cam, lut, nullptr, uncropped).image.rgba, ref.image.rgba);
}

}  // namespace
}  // namespace lacuna
