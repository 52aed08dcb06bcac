// write_volume -> read_volume round trips: voxels byte-identical, geometry preserved, writes
// atomic (no temporaries left behind).
#include <gtest/gtest.h>

#include <cmath>

#include "io/io_test_util.h"
#include "lacuna/io.h"

namespace lacuna {
namespace {

using test::ScratchDir;

void expect_same_geometry(const Volume& a, const Volume& b, double tol = 1e-6) {
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(a.spacing[i], b.spacing[i], tol) << "spacing axis " << i;
        EXPECT_NEAR(a.origin[i], b.origin[i], tol * 100) << "origin axis " << i;
    }
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(a.direction[i], b.direction[i], 1e-6) << i;
}

struct RoundTripCase {
    std::string name;
    VoxelType type;
    bool keeps_geometry = true;  // raw files carry no spacing/origin
};

class IoRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(IoRoundTrip, WritesAndReadsBackIdenticalVoxelsAndSpacing) {
    const RoundTripCase& c = GetParam();
    ScratchDir dir;
    const Volume v = test::pattern_volume({19, 14, 11}, c.type);
    const std::string path = dir.file(c.name);
    write_volume(path, v);
    const Volume back = read_volume(path);
    EXPECT_TRUE(test::same_voxels(v, back)) << to_string(back);
    if (c.keeps_geometry) expect_same_geometry(v, back);
    EXPECT_EQ(back.data_range().min, v.data_range().min);
    EXPECT_EQ(back.data_range().max, v.data_range().max);
    // Nothing but the output (and a detached data file) remains: the temporary is gone.
    for (const std::string& n : dir.names()) EXPECT_NE(n.rfind(".tmp-", 0), 0u) << n;
}

std::string case_name(const ::testing::TestParamInfo<RoundTripCase>& info) {
    std::string s = info.param.name + "_" + to_string(info.param.type);
    for (char& ch : s)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return s;
}

INSTANTIATE_TEST_SUITE_P(
    Io, IoRoundTrip,
    ::testing::Values(
        RoundTripCase{"vol.nrrd", VoxelType::UInt8}, RoundTripCase{"vol.nrrd", VoxelType::Int16},
        RoundTripCase{"vol.nrrd", VoxelType::UInt16}, RoundTripCase{"vol.nrrd", VoxelType::Float32},
        RoundTripCase{"vol.nhdr", VoxelType::UInt16}, RoundTripCase{"vol.nii", VoxelType::Int16},
        RoundTripCase{"vol.nii", VoxelType::Float32}, RoundTripCase{"vol.nii.gz", VoxelType::UInt8},
        RoundTripCase{"vol.nii.gz", VoxelType::UInt16},
        RoundTripCase{"vol.mha", VoxelType::Float32}, RoundTripCase{"vol.mha", VoxelType::Int16},
        RoundTripCase{"vol.mhd", VoxelType::UInt8},
        RoundTripCase{"vol_19x14x11_uint16.raw", VoxelType::UInt16, false},
        RoundTripCase{"vol_19x14x11_float32.raw", VoxelType::Float32, false}),
    case_name);

TEST(IoWriter, RoundTripsObliqueDirectionThroughNiftiAndNrrd) {
    ScratchDir dir;
    Volume v = test::pattern_volume({8, 7, 6}, VoxelType::Int16);
    // A rotation by 30 degrees about z (row-major direction cosines).
    const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
    const double rot[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    std::copy(rot, rot + 9, v.direction);
    for (const char* name : {"oblique.nii", "oblique.nrrd", "oblique.mha"}) {
        write_volume(dir.file(name), v);
        const Volume back = read_volume(dir.file(name));
        // NIfTI stores the geometry in single precision.
        expect_same_geometry(v, back, 1e-5);
        EXPECT_TRUE(test::same_voxels(v, back)) << name;
    }
}

TEST(IoWriter, DetachedHeadersReferenceTheFinalDataFile) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({9, 8, 7}, VoxelType::UInt8);
    write_volume(dir.file("head.nhdr"), v);
    write_volume(dir.file("meta.mhd"), v);
    const std::vector<std::string> names = dir.names();
    for (const std::string& n : names) EXPECT_NE(n.rfind(".tmp-", 0), 0u) << n;
    EXPECT_EQ(names.size(), 4u);  // two headers, two data files
    const std::string nhdr = [&] {
        auto b = test::file_bytes(dir.file("head.nhdr"));
        return std::string(b.begin(), b.end());
    }();
    EXPECT_EQ(nhdr.find(".tmp-"), std::string::npos) << nhdr;
    // Moving the pair elsewhere keeps it readable: the reference is relative.
    ScratchDir other;
    for (const std::string& n : names) std::filesystem::copy(dir.file(n), other.file(n));
    EXPECT_TRUE(test::same_voxels(v, read_volume(other.file("head.nhdr"))));
    EXPECT_TRUE(test::same_voxels(v, read_volume(other.file("meta.mhd"))));
}

TEST(IoWriter, OverwritesAnExistingFile) {
    ScratchDir dir;
    const Volume a = test::pattern_volume({5, 5, 5}, VoxelType::UInt8, 1);
    const Volume b = test::pattern_volume({6, 5, 4}, VoxelType::UInt8, 2);
    write_volume(dir.file("v.nrrd"), a);
    write_volume(dir.file("v.nrrd"), b);
    EXPECT_TRUE(test::same_voxels(b, read_volume(dir.file("v.nrrd"))));
    EXPECT_EQ(dir.names().size(), 1u);
}

TEST(IoWriter, NiiGzOutputIsGzipCompressed) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({16, 16, 16}, VoxelType::UInt8);
    write_volume(dir.file("v.nii.gz"), v);
    const auto bytes = test::file_bytes(dir.file("v.nii.gz"));
    ASSERT_GE(bytes.size(), 2u);
    EXPECT_EQ(bytes[0], 0x1f);
    EXPECT_EQ(bytes[1], 0x8b);
}

TEST(IoWriter, RoundTripsCh2ThroughNiiGz) {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    ASSERT_TRUE(std::filesystem::exists(ch2)) << ch2 << " is installed by scripts/install-deps";
    ScratchDir dir;
    const Volume v = read_volume(ch2);
    write_volume(dir.file("ch2.nii.gz"), v);
    const Volume back = read_volume(dir.file("ch2.nii.gz"));
    EXPECT_TRUE(test::same_voxels(v, back));
    expect_same_geometry(v, back);
}

TEST(IoWriter, RejectsUnknownExtension) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({4, 4, 4}, VoxelType::UInt8);
    const std::string msg = test::error_of([&] { write_volume(dir.file("v.tiff"), v); });
    EXPECT_NE(msg.find("v.tiff"), std::string::npos) << msg;
    EXPECT_TRUE(dir.names().empty());
}

TEST(IoWriter, UnwritableDirectoryThrowsAndLeavesNothing) {
    ScratchDir dir;
    const auto locked = dir.path() / "locked";
    std::filesystem::create_directory(locked);
    std::filesystem::permissions(
        locked, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const Volume v = test::pattern_volume({4, 4, 4}, VoxelType::UInt8);
    for (const char* name : {"v.nrrd", "v.nii.gz", "v.mhd", "v_4x4x4_uint8.raw"}) {
        const std::string path = (locked / name).string();
        EXPECT_TRUE(test::as_unprivileged([&] {
            const std::string msg = test::quiet_error_of([&] { write_volume(path, v); });
            return msg.find(name) != std::string::npos &&
                   msg.find("cannot write") != std::string::npos &&
                   msg.find('\n') == std::string::npos;
        })) << name;
    }
    std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
    EXPECT_TRUE(std::filesystem::is_empty(locked));
}

TEST(IoWriter, FailedFinalRenameLeavesNoTemporaryOrDataFile) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({4, 4, 4}, VoxelType::UInt8);
    // A directory squatting on the output name makes the last step (rename) fail.
    for (const char* name : {"v.nrrd", "v.nhdr", "v.mhd", "v.nii.gz", "v_4x4x4_uint8.raw"}) {
        std::filesystem::create_directory(dir.path() / name);
        const std::string msg = test::error_of([&] { write_volume(dir.file(name), v); });
        EXPECT_NE(msg.find("cannot write"), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        std::filesystem::remove(dir.path() / name);
        EXPECT_TRUE(dir.names().empty()) << name << " left " << dir.names().front();
    }
}

TEST(IoWriter, MissingDirectorySaysCannotWrite) {
    ScratchDir dir;
    const std::string path = dir.file("absent/v.nrrd");
    const std::string msg = test::error_of([&] {
        write_volume(path, test::pattern_volume({4, 4, 4}, VoxelType::UInt8));
    });
    EXPECT_EQ(msg, path + ": output: cannot write: No such file or directory");
}

TEST(IoDicom, WritesAndReadsBackASeries) {
    ScratchDir dir;
    for (VoxelType type : {VoxelType::Int16, VoxelType::UInt16, VoxelType::UInt8}) {
        const Volume v = test::pattern_volume({12, 10, 6}, type);
        const std::string series = dir.file(to_string(type)) + "/";
        write_volume(series, v);
        EXPECT_EQ(std::distance(std::filesystem::directory_iterator(series),
                                std::filesystem::directory_iterator()),
                  6);
        const Volume back = read_volume(series);
        EXPECT_TRUE(test::same_voxels(v, back)) << to_string(back);
        expect_same_geometry(v, back, 1e-4);
        // Without the trailing slash the folder is read the same way.
        const Volume again = read_volume(dir.file(to_string(type)));
        EXPECT_TRUE(test::same_voxels(v, again));
    }
}

TEST(IoDicom, RejectsFloatVolumes) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({4, 4, 4}, VoxelType::Float32);
    const std::string msg = test::error_of([&] { write_volume(dir.file("f") + "/", v); });
    EXPECT_NE(msg.find("float32"), std::string::npos) << msg;
}

}  // namespace
}  // namespace lacuna
