// The NIfTI reader on hand-built headers: NIfTI-2, byte order, type conversions, scaling,
// 4D files with one time point. (The real templates are covered in volume_reader_test.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "io/io_test_util.h"
#include "io/nifti_test_file.h"
#include "lacuna/io.h"

namespace lacuna {
namespace {

using test::NiftiSpec;
using test::ScratchDir;

TEST(IoNifti, ReadsNifti2WithSform) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.version = 2;
    spec.dims = {4, 3, 2};
    spec.datatype = 512;  // uint16
    spec.pixdim = {2, 3, 4};
    spec.sform_code = 1;
    spec.srow = {{{2, 0, 0, 10}, {0, 3, 0, 20}, {0, 0, 4, 30}}};
    std::vector<uint16_t> vox(24);
    for (size_t i = 0; i < vox.size(); ++i) vox[i] = uint16_t(1000 + i);
    const std::string path = dir.file("two.nii");
    test::write_bytes(path, test::nifti_bytes(spec, vox.data(), vox.size() * 2));
    const Volume v = read_volume(path);
    EXPECT_EQ(v.dims(), (Vec3i{4, 3, 2}));
    EXPECT_EQ(v.type(), VoxelType::UInt16);
    EXPECT_EQ(v.spacing, (Vec3d{2, 3, 4}));
    EXPECT_EQ(v.origin, (Vec3d{-10, -20, 30}));  // RAS -> LPS
    EXPECT_EQ(v.value(3, 2, 1), 1023.f);
    EXPECT_EQ(v.data_range().min, 1000.f);
}

TEST(IoNifti, ReadsBigEndianNifti1) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {3, 3, 3};
    spec.datatype = 4;  // int16
    spec.big_endian = true;
    std::vector<int16_t> vox(27);
    for (size_t i = 0; i < vox.size(); ++i) vox[i] = int16_t(-300 + 25 * int(i));
    std::vector<int16_t> be = vox;
    for (auto& x : be) x = int16_t(uint16_t(x) >> 8 | uint16_t(x) << 8);
    const std::string path = dir.file("be.nii");
    test::write_bytes(path, test::nifti_bytes(spec, be.data(), be.size() * 2));
    const Volume v = read_volume(path);
    ASSERT_EQ(v.type(), VoxelType::Int16);
    EXPECT_EQ(std::memcmp(v.data(), vox.data(), vox.size() * 2), 0);
}

TEST(IoNifti, WidensInt8ToInt16) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {2, 2, 2};
    spec.datatype = 256;  // int8
    const int8_t vox[8] = {-128, -1, 0, 1, 2, 3, 64, 127};
    const std::string path = dir.file("i8.nii");
    test::write_bytes(path, test::nifti_bytes(spec, vox, sizeof vox));
    const Volume v = read_volume(path);
    ASSERT_EQ(v.type(), VoxelType::Int16);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(v.data_as<int16_t>()[i], vox[i]);
}

TEST(IoNifti, ConvertsFloat64AndInt32ToFloat32) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {2, 2, 2};
    spec.datatype = 64;  // float64
    const double d[8] = {-1.5, 0, 0.25, 1e6, 3, 4, 5, 6};
    test::write_bytes(dir.file("f64.nii"), test::nifti_bytes(spec, d, sizeof d));
    const Volume v = read_volume(dir.file("f64.nii"));
    ASSERT_EQ(v.type(), VoxelType::Float32);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(v.data_as<float>()[i], float(d[i]));

    spec.datatype = 8;  // int32
    const int32_t n[8] = {-100000, 0, 1, 2, 3, 4, 5, 16777216};
    test::write_bytes(dir.file("i32.nii.gz"), test::gzip(test::nifti_bytes(spec, n, sizeof n)));
    const Volume w = read_volume(dir.file("i32.nii.gz"));
    ASSERT_EQ(w.type(), VoxelType::Float32);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(w.data_as<float>()[i], float(n[i]));
}

TEST(IoNifti, AppliesSlopeAndInterceptAsFloat) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {2, 2, 2};
    spec.datatype = 2;  // uint8
    spec.slope = 0.5;
    spec.inter = -10;
    const uint8_t vox[8] = {0, 1, 2, 3, 4, 100, 200, 255};
    test::write_bytes(dir.file("s.nii"), test::nifti_bytes(spec, vox, sizeof vox));
    const Volume v = read_volume(dir.file("s.nii"));
    ASSERT_EQ(v.type(), VoxelType::Float32);
    for (int i = 0; i < 8; ++i) EXPECT_FLOAT_EQ(v.data_as<float>()[i], vox[i] * 0.5f - 10.f);
}

// A 4D file: each frame is its own volume (frames stored one after another after vox_offset),
// uncompressed and gzipped, NIfTI-1 and -2; the frame is range-checked against dim[4], and a
// file whose last frame is cut is truncated for that frame only.
TEST(IoNifti, ReadsTheChosenVolumeOfAFourDimensionalFile) {
    ScratchDir dir;
    for (const int version : {1, 2})
        for (const bool gz : {false, true}) {
            NiftiSpec spec;
            spec.version = version;
            spec.ndim = 4;
            spec.dims = {3, 2, 2};
            spec.dim4 = 3;
            spec.datatype = 512;  // uint16
            std::vector<uint16_t> vox(12 * 3);
            for (size_t i = 0; i < vox.size(); ++i) vox[i] = uint16_t(1000 * (i / 12) + i % 12 + 1);
            std::vector<uint8_t> bytes = test::nifti_bytes(spec, vox.data(), vox.size() * 2);
            const std::string name = "t" + std::to_string(version) + (gz ? ".nii.gz" : ".nii");
            test::write_bytes(dir.file(name), gz ? test::gzip(bytes) : bytes);
            for (int64_t frame = 0; frame < 3; ++frame) {
                ReadOptions ro;
                ro.frame = frame;
                const Volume v = read_volume(dir.file(name), ro);
                ASSERT_EQ(v.dims(), (Vec3i{3, 2, 2})) << name;
                for (int i = 0; i < 12; ++i)
                    ASSERT_EQ(v.data_as<uint16_t>()[i], vox[size_t(12 * frame + i)])
                        << name << " " << frame;
            }
            for (const int64_t bad : {int64_t(3), int64_t(-1), int64_t(1) << 40}) {
                ReadOptions ro;
                ro.frame = bad;
                const std::string msg = test::error_of([&] { read_volume(dir.file(name), ro); });
                EXPECT_NE(msg.find(name + ": frame: expected 0..2, got " + std::to_string(bad)),
                          std::string::npos)
                    << msg;
            }
            if (!gz) {  // the last frame cut in half: frames 0 and 1 read, frame 2 is truncated
                bytes.resize(bytes.size() - 12);
                test::write_bytes(dir.file("cut" + name), bytes);
                ReadOptions ro;
                ro.frame = 1;
                EXPECT_EQ(read_volume(dir.file("cut" + name), ro).data_as<uint16_t>()[0], 1001);
                ro.frame = 2;
                const std::string msg =
                    test::error_of([&] { read_volume(dir.file("cut" + name), ro); });
                EXPECT_NE(
                    msg.find("voxel data: truncated: expected 24 bytes of voxels after offset"),
                    std::string::npos)
                    << msg;
                EXPECT_NE(msg.find("(volume 2), the file has 12"), std::string::npos) << msg;
            }
        }
}

// A two-file NIfTI (name.hdr + name.img or name.img.gz; magic ni1 / ni2, vox_offset counted in
// the .img) reads as the one-file .nii with the same header and voxels, named by either file;
// a missing or short .img is an error naming it; a .nii with a pair's magic and an Analyze
// header (no magic) are refused.
TEST(IoNifti, ReadsTwoFilePairsAsTheirOneFileNii) {
    ScratchDir dir;
    for (const int version : {1, 2}) {
        NiftiSpec spec;
        spec.version = version;
        spec.dims = {4, 3, 2};
        spec.ndim = 4;
        spec.dim4 = 2;
        spec.datatype = 4;  // int16
        spec.pixdim = {0.5, 1.5, 2};
        spec.sform_code = 1;
        spec.srow = {{{-0.5, 0, 0, 10}, {0, 1.5, 0, -4}, {0, 0, 2, 3}}};
        std::vector<int16_t> vox(48);
        for (size_t i = 0; i < vox.size(); ++i) vox[i] = int16_t(37 * int(i) - 700);
        const std::string v = std::to_string(version);
        test::write_bytes(dir.file("one" + v + ".nii"), test::nifti_bytes(spec, vox.data(), 96));
        spec.magic = version == 1 ? std::string("ni1\0", 4) : std::string("ni2\0\r\n\032\n", 8);
        spec.vox_offset = 16;  // in the .img
        std::vector<uint8_t> hdr = test::nifti_bytes(spec, nullptr, 0);
        hdr.resize(version == 1 ? 348 : 540);
        std::vector<uint8_t> img(16, 0);
        img.insert(img.end(), reinterpret_cast<const uint8_t*>(vox.data()),
                   reinterpret_cast<const uint8_t*>(vox.data()) + 96);
        test::write_bytes(dir.file("pair" + v + ".hdr"), hdr);
        test::write_bytes(dir.file("pair" + v + ".img"), img);
        test::write_bytes(dir.file("gz" + v + ".hdr"), hdr);
        test::write_bytes(dir.file("gz" + v + ".img.gz"), test::gzip(img));
        for (const int64_t frame : {0, 1}) {
            ReadOptions ro;
            ro.frame = frame;
            const Volume ref = read_volume(dir.file("one" + v + ".nii"), ro);
            for (const char* name : {"pair", "gz"})
                for (const char* ext : {".hdr", ".img"}) {
                    const std::string file = dir.file(
                        name + v +
                        (ext == std::string(".img") && name == std::string("gz") ? ".img.gz"
                                                                                 : ext));
                    const Volume got = read_volume(file, ro);
                    ASSERT_EQ(got.dims(), ref.dims()) << file;
                    EXPECT_EQ(0, std::memcmp(got.data(), ref.data(), 24 * 2))
                        << file << " frame " << frame;
                    EXPECT_EQ(to_string(got.spacing), to_string(ref.spacing)) << file;
                    EXPECT_EQ(to_string(got.origin), to_string(ref.origin)) << file;
                    for (int i = 0; i < 9; ++i)
                        EXPECT_EQ(got.direction[i], ref.direction[i]) << file;
                }
        }
        ReadOptions ro;
        ro.frame = 1;
        test::write_bytes(dir.file("short" + v + ".hdr"), hdr);
        test::write_bytes(dir.file("short" + v + ".img"),
                          std::vector<uint8_t>(img.begin(), img.end() - 2));
        std::string msg = test::error_of([&] { read_volume(dir.file("short" + v + ".hdr"), ro); });
        EXPECT_NE(msg.find("short" + v + ".img: voxel data: truncated"), std::string::npos) << msg;
        test::write_bytes(dir.file("lonely" + v + ".hdr"), hdr);
        msg = test::error_of([&] { read_volume(dir.file("lonely" + v + ".hdr"), ro); });
        EXPECT_NE(msg.find("lonely" + v + ".img: file: does not exist"), std::string::npos) << msg;
        test::write_bytes(dir.file("wrong" + v + ".nii"), test::nifti_bytes(spec, vox.data(), 96));
        msg = test::error_of([&] { read_volume(dir.file("wrong" + v + ".nii"), ro); });
        EXPECT_NE(msg.find("the header says its voxels are in a separate .img file"),
                  std::string::npos)
            << msg;
    }
    NiftiSpec analyze;
    analyze.magic = std::string("\0\0\0\0", 4);
    analyze.vox_offset = 16;
    std::vector<uint8_t> hdr = test::nifti_bytes(analyze, nullptr, 0);
    hdr.resize(348);
    test::write_bytes(dir.file("analyze.hdr"), hdr);
    test::write_bytes(dir.file("analyze.img"), std::vector<uint8_t>(24, 1));
    const std::string msg = test::error_of([&] { read_volume(dir.file("analyze.hdr")); });
    EXPECT_NE(
        msg.find(
            "analyze.hdr: header: not a NIfTI-1 pair header (magic 'ni1' missing; Analyze 7.5"),
        std::string::npos)
        << msg;
}

// A 3D file takes frame 0 only; other formats take no frame but 0.
TEST(IoNifti, AThreeDimensionalFileHasOneFrame) {
    ScratchDir dir;
    NiftiSpec spec;
    const uint8_t vox[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    test::write_bytes(dir.file("one.nii"), test::nifti_bytes(spec, vox, sizeof vox));
    ReadOptions ro;
    ro.frame = 0;
    EXPECT_EQ(read_volume(dir.file("one.nii"), ro).data_as<uint8_t>()[7], 8);
    ro.frame = 1;
    EXPECT_NE(test::error_of([&] {
                  read_volume(dir.file("one.nii"), ro);
              }).find("one.nii: frame: expected 0..0 (the file holds one volume), got 1"),
              std::string::npos);
    const Volume v = read_volume(dir.file("one.nii"));
    write_volume(dir.file("one.nrrd"), v);
    EXPECT_NE(test::error_of([&] {
                  read_volume(dir.file("one.nrrd"), ro);
              }).find("one.nrrd: frame: expected 0: this format is read as one volume"),
              std::string::npos);
    ro.frame = 0;
    EXPECT_EQ(read_volume(dir.file("one.nrrd"), ro).dims(), v.dims());
}

TEST(IoNifti, AcceptsFourthDimensionOfOne) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.ndim = 4;
    spec.dims = {3, 2, 2};
    spec.datatype = 2;
    const uint8_t vox[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    test::write_bytes(dir.file("t1.nii"), test::nifti_bytes(spec, vox, sizeof vox));
    EXPECT_EQ(read_volume(dir.file("t1.nii")).dims(), (Vec3i{3, 2, 2}));
}

}  // namespace
}  // namespace lacuna
