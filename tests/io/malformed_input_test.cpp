// Every kind of bad input must end in one lacuna::Error line that names the file and the
// problem: no crash, no abort, no huge allocation, no stray output, input left untouched.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>

#include "io/io_test_util.h"
#include "io/nifti_test_file.h"
#include "lacuna/io.h"
#include "lacuna/rgb.h"

namespace lacuna {
namespace {

using test::NiftiSpec;
using test::ScratchDir;

// Reads `path`, expecting lacuna::Error; checks the message names the file, is one line and
// mentions every string in `expect` (case-sensitive), and that the file bytes are unchanged.
std::string expect_read_error(const std::string& path, std::initializer_list<std::string> expect,
                              const ReadOptions& opts = {}) {
    const bool is_file = std::filesystem::is_regular_file(path);
    const std::vector<uint8_t> before = is_file ? test::file_bytes(path) : std::vector<uint8_t>{};
    const std::string msg = test::error_of([&] { read_volume(path, opts); });
    const std::string name = std::filesystem::path(path).filename().string();
    EXPECT_NE(msg.find(name.empty() ? path : name), std::string::npos)
        << "message does not name the file: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message spans lines: " << msg;
    EXPECT_LT(msg.size(), 600u) << msg;
    for (const std::string& e : expect)
        EXPECT_NE(msg.find(e), std::string::npos) << "expected '" << e << "' in: " << msg;
    if (is_file) {
        EXPECT_EQ(test::file_bytes(path), before) << "the input was modified";
    }
    // LACUNA_SHOW_ERRORS=1 prints every message, for reviewing their wording.
    if (std::getenv("LACUNA_SHOW_ERRORS")) std::printf("    %s\n", msg.c_str());
    return msg;
}

std::string nrrd_header(const std::string& type, const std::string& sizes, int dimension = 3,
                        const std::string& extra = "") {
    return "NRRD0004\ntype: " + type + "\ndimension: " + std::to_string(dimension) +
           "\nsizes: " + sizes + "\nencoding: raw\nendian: little\n" + extra + "\n";
}

// ---------------------------------------------------------------------------------------------
// Files that are not there or not files

TEST(IoMalformed, MissingFileSaysDoesNotExist) {
    ScratchDir dir;
    expect_read_error(dir.file("nope.nii.gz"), {"does not exist"});
    expect_read_error(dir.file("nope.nrrd"), {"does not exist"});
}

TEST(IoMalformed, EmptyFolderHasNoDicomSeries) {
    ScratchDir dir;
    std::filesystem::create_directory(dir.path() / "empty");
    expect_read_error(dir.file("empty"), {"no DICOM series"});
}

TEST(IoMalformed, FolderOfNonDicomFilesHasNoDicomSeries) {
    ScratchDir dir;
    std::filesystem::create_directory(dir.path() / "junk");
    test::write_text(dir.file("junk/a.dcm"), "this is not DICOM\n");
    test::write_text(dir.file("junk/b.txt"), std::string(4096, 'x'));
    expect_read_error(dir.file("junk"), {"no DICOM series"});
}

TEST(IoMalformed, SingleDicomSliceIsNotAVolume) {
    ScratchDir dir;
    const Volume v = test::pattern_volume({8, 8, 2}, VoxelType::Int16);
    write_volume(dir.file("two") + "/", v);
    std::filesystem::remove(dir.path() / "two" / "slice_00001.dcm");
    expect_read_error(dir.file("two"), {"dims"});
}

TEST(IoMalformed, EmptyFileIsRejected) {
    ScratchDir dir;
    for (const char* name : {"empty.nii", "empty.nii.gz", "empty.nrrd", "empty.mha"}) {
        test::write_text(dir.file(name), "");
        expect_read_error(dir.file(name), {});
    }
}

// ---------------------------------------------------------------------------------------------
// Wrong magic

TEST(IoMalformed, TextFileRenamedNiiHasWrongMagic) {
    ScratchDir dir;
    std::string text;
    for (int i = 0; i < 40; ++i) text += "The quick brown fox jumps over the lazy dog.\n";
    test::write_text(dir.file("notes.nii"), text);
    expect_read_error(dir.file("notes.nii"), {"not a NIfTI file"});
    test::write_bytes(dir.file("notes.nii.gz"), test::gzip({text.begin(), text.end()}));
    expect_read_error(dir.file("notes.nii.gz"), {"not a NIfTI file"});
}

TEST(IoMalformed, TextFileRenamedNrrdOrMhaIsRejected) {
    ScratchDir dir;
    test::write_text(dir.file("notes.nrrd"), "hello\nworld\n");
    expect_read_error(dir.file("notes.nrrd"), {"NRRD"});
    test::write_text(dir.file("notes.mha"), "hello\nworld\n");
    expect_read_error(dir.file("notes.mha"), {"MetaImage"});
}

TEST(IoMalformed, Nifti1WithoutMagicIsRejected) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.magic = std::string("xyz\0", 4);
    const uint8_t vox[8] = {};
    test::write_bytes(dir.file("nomagic.nii"), test::nifti_bytes(spec, vox, 8));
    expect_read_error(dir.file("nomagic.nii"), {"magic"});
}

TEST(IoMalformed, UnknownExtensionWithUnknownContent) {
    ScratchDir dir;
    test::write_text(dir.file("volume.xyz"), std::string(1000, '\x01'));
    expect_read_error(dir.file("volume.xyz"), {});
}

// ---------------------------------------------------------------------------------------------
// Truncated data

TEST(IoMalformed, NiiGzCutInHalfIsTruncated) {
    const std::string ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
    ASSERT_TRUE(std::filesystem::exists(ch2)) << ch2 << " is installed by scripts/install-deps";
    ScratchDir dir;
    std::vector<uint8_t> bytes = test::file_bytes(ch2);
    bytes.resize(bytes.size() / 2);
    test::write_bytes(dir.file("half.nii.gz"), bytes);
    expect_read_error(dir.file("half.nii.gz"), {"truncated"});
}

TEST(IoMalformed, NiiCutShortIsTruncatedBeforeAllocating) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {1000, 1000, 1000};  // 1 GB of uint8 promised, 10 bytes present
    const uint8_t vox[10] = {};
    std::vector<uint8_t> bytes = test::nifti_bytes(spec, vox, sizeof vox);
    test::write_bytes(dir.file("short.nii"), bytes);
    expect_read_error(dir.file("short.nii"), {"truncated", "1000000000"});
}

TEST(IoMalformed, HeaderOnlyHalfPresent) {
    ScratchDir dir;
    NiftiSpec spec;
    std::vector<uint8_t> bytes = test::nifti_bytes(spec, nullptr, 0);
    bytes.resize(200);
    test::write_bytes(dir.file("halfheader.nii"), bytes);
    expect_read_error(dir.file("halfheader.nii"), {"truncated"});
}

TEST(IoMalformed, CorruptGzipStreamIsReported) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {64, 64, 64};
    std::vector<uint8_t> vox(64 * 64 * 64);
    for (size_t i = 0; i < vox.size(); ++i) vox[i] = uint8_t(i * 7 + i / 100);
    std::vector<uint8_t> gz = test::gzip(test::nifti_bytes(spec, vox.data(), vox.size()));
    for (size_t i = gz.size() / 3; i < gz.size() / 3 + 64; ++i) gz[i] ^= 0x5a;
    test::write_bytes(dir.file("corrupt.nii.gz"), gz);
    expect_read_error(dir.file("corrupt.nii.gz"), {});
}

TEST(IoMalformed, NrrdWithShortDataIsRejected) {
    ScratchDir dir;
    std::string text = nrrd_header("uint8", "16 16 16");
    text += std::string(100, 'a');  // 4096 promised
    test::write_text(dir.file("short.nrrd"), text);
    expect_read_error(dir.file("short.nrrd"), {});
}

TEST(IoMalformed, GzipNrrdCutShortIsRejected) {
    ScratchDir dir;
    std::vector<uint8_t> vox(32 * 32 * 32, 7);
    std::vector<uint8_t> gz = test::gzip(vox);
    gz.resize(gz.size() / 2);
    std::string text = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 32 32 32\nencoding: gzip\n\n";
    std::vector<uint8_t> bytes(text.begin(), text.end());
    bytes.insert(bytes.end(), gz.begin(), gz.end());
    test::write_bytes(dir.file("cut.nrrd"), bytes);
    expect_read_error(dir.file("cut.nrrd"), {});
}

TEST(IoMalformed, DetachedHeaderWithMissingDataFile) {
    ScratchDir dir;
    test::write_text(dir.file("lonely.nhdr"),
                     nrrd_header("uint8", "4 4 4", 3, "data file: lonely.raw\n"));
    expect_read_error(dir.file("lonely.nhdr"), {});
    test::write_text(dir.file("lonely.mhd"),
                     "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                     "ElementDataFile = lonely.raw\n");
    expect_read_error(dir.file("lonely.mhd"), {});
}

// Found by fuzz_nrrd: a "data file:" value of whitespace that trim() keeps (a form feed)
// split into no words at all, and the reader indexed the first of them.
TEST(IoMalformed, NrrdDataFileOfOnlyWhitespaceIsRejected) {
    ScratchDir dir;
    const std::string found = "\x01NRRD20at)\ndata file:\x0c";
    test::write_bytes(dir.file("ff.nhdr"), std::vector<uint8_t>(found.begin(), found.end()));
    expect_read_error(dir.file("ff.nhdr"), {});
    test::write_text(dir.file("ff2.nhdr"), nrrd_header("uint8", "4 4 4", 3, "data file: \x0c\v\n"));
    expect_read_error(dir.file("ff2.nhdr"), {"data file"});
}

TEST(IoMalformed, MhaWithShortDataIsRejected) {
    ScratchDir dir;
    std::string text =
        "ObjectType = Image\nNDims = 3\nDimSize = 16 16 16\nElementType = MET_SHORT\n"
        "ElementDataFile = LOCAL\n";
    text += std::string(300, 'b');
    test::write_text(dir.file("short.mha"), text);
    expect_read_error(dir.file("short.mha"), {});
}

std::string compressed_mha(const std::vector<uint8_t>& zdata, bool with_size) {
    std::string text =
        "ObjectType = Image\nNDims = 3\nDimSize = 32 32 32\nElementType = MET_UCHAR\n"
        "CompressedData = True\n";
    if (with_size) text += "CompressedDataSize = " + std::to_string(zdata.size()) + "\n";
    text += "ElementDataFile = LOCAL\n";
    text.append(reinterpret_cast<const char*>(zdata.data()), zdata.size());
    return text;
}

std::vector<uint8_t> zlib_compress(const std::vector<uint8_t>& in) {
    uLongf n = compressBound(uLong(in.size()));
    std::vector<uint8_t> out(n);
    compress(out.data(), &n, in.data(), uLong(in.size()));
    out.resize(n);
    return out;
}

TEST(IoMalformed, CompressedMhaCutShortOrCorruptIsRejected) {
    ScratchDir dir;
    std::vector<uint8_t> vox(32 * 32 * 32);
    for (size_t i = 0; i < vox.size(); ++i) vox[i] = uint8_t(i * 7 + i / 300);
    const std::vector<uint8_t> z = zlib_compress(vox);
    // The intact file reads back exactly: the failures below are about the damage.
    test::write_text(dir.file("ok.mha"), compressed_mha(z, true));
    const Volume ok = read_volume(dir.file("ok.mha"));
    EXPECT_EQ(std::memcmp(ok.data(), vox.data(), vox.size()), 0);

    std::vector<uint8_t> cut(z.begin(), z.begin() + long(z.size() / 2));
    test::write_text(dir.file("cut.mha"), compressed_mha(cut, true));
    expect_read_error(dir.file("cut.mha"), {"truncated"});
    test::write_text(dir.file("cut_nosize.mha"), compressed_mha(cut, false));
    expect_read_error(dir.file("cut_nosize.mha"), {"truncated"});
    std::vector<uint8_t> bad = z;
    for (size_t i = 20; i < 120 && i < bad.size(); ++i) bad[i] ^= 0x55;
    test::write_text(dir.file("bad.mha"), compressed_mha(bad, true));
    expect_read_error(dir.file("bad.mha"), {"voxel data"});
}

TEST(IoMalformed, MhdWithShortExternalDataIsRejected) {
    ScratchDir dir;
    test::write_text(dir.file("ext.mhd"),
                     "ObjectType = Image\nNDims = 3\nDimSize = 8 8 8\nElementType = MET_FLOAT\n"
                     "ElementDataFile = ext.raw\n");
    test::write_bytes(dir.file("ext.raw"), std::vector<uint8_t>(8 * 8 * 8 * 4 - 1, 0));
    expect_read_error(dir.file("ext.mhd"), {"truncated", "2048"});
}

TEST(IoMalformed, BigEndianMhaReadsCorrectly) {
    ScratchDir dir;
    std::string text =
        "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_USHORT\n"
        "BinaryDataByteOrderMSB = True\nElementSpacing = 0.5 1 2\nElementDataFile = LOCAL\n";
    for (int i = 0; i < 8; ++i) {
        text += char((1000 + i) >> 8);
        text += char((1000 + i) & 0xff);
    }
    test::write_text(dir.file("be.mha"), text);
    const Volume v = read_volume(dir.file("be.mha"));
    ASSERT_EQ(v.type(), VoxelType::UInt16);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(v.data_as<uint16_t>()[i], 1000 + i);
    EXPECT_EQ(v.spacing, (Vec3d{0.5, 1, 2}));
}

TEST(IoMalformed, RawFileOfWrongSizeNamesBothSizes) {
    ScratchDir dir;
    test::write_bytes(dir.file("head_10x10x10_uint16.raw"), std::vector<uint8_t>(1999, 0));
    expect_read_error(dir.file("head_10x10x10_uint16.raw"), {"2000", "1999"});
}

TEST(IoMalformed, RawFileWithoutLayoutIsRejected) {
    ScratchDir dir;
    test::write_bytes(dir.file("mystery.raw"), std::vector<uint8_t>(1000, 0));
    expect_read_error(dir.file("mystery.raw"), {"raw layout"});
}

// ---------------------------------------------------------------------------------------------
// Absurd or unsupported shapes

TEST(IoMalformed, NrrdWithHugeSizesFailsBeforeAllocating) {
    ScratchDir dir;
    test::write_text(dir.file("huge.nrrd"), nrrd_header("uint8", "100000 100000 100000"));
    expect_read_error(dir.file("huge.nrrd"), {"dims"});
}

TEST(IoMalformed, NrrdWhoseSizeProductOverflowsIsRejected) {
    ScratchDir dir;
    test::write_text(dir.file("overflow.nrrd"),
                     nrrd_header("uint8", "4294967296 4294967296 4294967296"));
    expect_read_error(dir.file("overflow.nrrd"), {});
    test::write_text(dir.file("overflow2.nrrd"), nrrd_header("float", "18446744073709551615 3 3"));
    expect_read_error(dir.file("overflow2.nrrd"), {});
}

TEST(IoMalformed, NrrdThatWouldNotFitInMemoryIsRejected) {
    ScratchDir dir;
    // 32768^3 floats = 128 TiB: every axis is legal, the product is not.
    test::write_text(dir.file("big.nrrd"), nrrd_header("float", "32768 32768 32768"));
    expect_read_error(dir.file("big.nrrd"), {"needs 141 TB, more than the memory budget"});
}

TEST(IoMalformed, MhaWithHugeSizesFailsBeforeAllocating) {
    ScratchDir dir;
    test::write_text(dir.file("huge.mha"),
                     "ObjectType = Image\nNDims = 3\nDimSize = 100000 100000 100000\n"
                     "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n");
    expect_read_error(dir.file("huge.mha"), {"dims"});
}

TEST(IoMalformed, NiftiWithNegativeOrTinyDimsIsRejected) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.dims = {-5, 4, 4};
    test::write_bytes(dir.file("neg.nii"), test::nifti_bytes(spec, nullptr, 0));
    expect_read_error(dir.file("neg.nii"), {"dims"});
    spec.dims = {1, 4, 4};
    const uint8_t vox[16] = {};
    test::write_bytes(dir.file("flat.nii"), test::nifti_bytes(spec, vox, 16));
    expect_read_error(dir.file("flat.nii"), {"dims"});
}

TEST(IoMalformed, TwoDimensionalImagesAreRejected) {
    ScratchDir dir;
    std::string text = nrrd_header("uint8", "8 8", 2) + std::string(64, 'x');
    test::write_text(dir.file("flat.nrrd"), text);
    expect_read_error(dir.file("flat.nrrd"), {"3D"});
    NiftiSpec spec;
    spec.ndim = 2;
    spec.dims = {8, 8, 1};
    std::vector<uint8_t> vox(64);
    test::write_bytes(dir.file("flat.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("flat.nii"), {"3D"});
}

TEST(IoMalformed, TimeSeriesNeedAFrameButOneTimePointDoesNot) {
    ScratchDir dir;
    std::string ok = nrrd_header("uint8", "4 4 4 1", 4) + std::string(64, 'x');
    test::write_text(dir.file("t1.nrrd"), ok);
    EXPECT_EQ(read_volume(dir.file("t1.nrrd")).dims(), (Vec3i{4, 4, 4}));
    std::string bad = nrrd_header("uint8", "4 4 4 3", 4) + std::string(192, 'x');
    test::write_text(dir.file("t3.nrrd"), bad);
    expect_read_error(dir.file("t3.nrrd"), {"3D"});
    NiftiSpec spec;
    spec.ndim = 4;
    spec.dims = {4, 4, 4};
    spec.dim4 = 3;
    std::vector<uint8_t> vox(192);
    test::write_bytes(dir.file("t3.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    // A 4D NIfTI file is read volume by volume (ReadOptions::frame); without one it says how
    // many it holds. Other formats' 4D images stay refused.
    expect_read_error(dir.file("t3.nii"),
                      {"frame: the file holds 3 volumes along dim[4]; choose one (0..2)"});
}

// RGB NRRD is not read (yet); RGB NIfTI is (docs/formats.md, "RGB volumes"), but one whose
// bitpix disagrees with its datatype is refused naming the field.
TEST(IoMalformed, RgbNrrdIsNotScalarAndAMisdeclaredRgbNiftiIsRefused) {
    ScratchDir dir;
    std::string text =
        nrrd_header("uint8", "3 4 4 4", 4, "kinds: RGB-color domain domain domain\n") +
        std::string(192, 'x');
    test::write_text(dir.file("rgb.nrrd"), text);
    expect_read_error(dir.file("rgb.nrrd"), {"expected a scalar image, got 3 components"});
    NiftiSpec spec;
    spec.datatype = 128;  // RGB24
    std::vector<uint8_t> vox(24);
    test::write_bytes(dir.file("rgb.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    EXPECT_NE(rgb_colours(read_volume(dir.file("rgb.nii"))), nullptr);
    spec.bitpix = 16;
    test::write_bytes(dir.file("bad.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("bad.nii"),
                      {"bitpix: expected 24 for RGB24 (datatype 128), got 16"});
}

TEST(IoMalformed, ComplexImagesAreRejected) {
    ScratchDir dir;
    std::string text = nrrd_header("float", "2 4 4 4", 4, "kinds: complex domain domain domain\n") +
                       std::string(4 * 128, '\0');
    test::write_text(dir.file("complex.nrrd"), text);
    expect_read_error(dir.file("complex.nrrd"), {"scalar"});
    NiftiSpec spec;
    spec.datatype = 32;  // complex64
    std::vector<uint8_t> vox(64);
    test::write_bytes(dir.file("complex.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("complex.nii"), {"complex"});
}

TEST(IoMalformed, UnknownNiftiDatatypeIsRejected) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.datatype = 999;
    std::vector<uint8_t> vox(8);
    test::write_bytes(dir.file("odd.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("odd.nii"), {"datatype"});
}

TEST(IoMalformed, NiftiVoxOffsetInsideHeaderIsRejected) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.vox_offset = 100;
    std::vector<uint8_t> vox(8);
    test::write_bytes(dir.file("offset.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("offset.nii"), {"vox_offset"});
}

TEST(IoMalformed, APairsHeaderNamedNiiIsRejected) {  // (pairs are read as .hdr + .img)
    ScratchDir dir;
    NiftiSpec spec;
    spec.magic = std::string("ni1\0", 4);
    std::vector<uint8_t> vox(8);
    test::write_bytes(dir.file("pair.nii"), test::nifti_bytes(spec, vox.data(), vox.size()));
    expect_read_error(dir.file("pair.nii"),
                      {"separate .img file (magic 'ni1'): name it .hdr beside its .img"});
}

// ---------------------------------------------------------------------------------------------
// Non-finite values

// NaN is background (docs/formats.md): each NaN voxel reads as the smallest finite value.
TEST(IoMalformed, NanInFloatNiftiReadsAsTheMinimum) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.datatype = 16;
    std::vector<float> vox = {3.f, -2.5f, 7.f, 1.f, 4.f, 0.f, 9.f, 2.f};
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> with_nan = vox;
    with_nan[5] = nan;  // voxel (1,0,1)
    with_nan[6] = nan;
    test::write_bytes(dir.file("nan.nii.gz"),
                      test::gzip(test::nifti_bytes(spec, with_nan.data(), with_nan.size() * 4)));
    const Volume v = read_volume(dir.file("nan.nii.gz"));
    EXPECT_EQ(v.nan_voxels, 2u);
    // Brute force: the minimum over the voxels that are not NaN, in place of each NaN.
    float lo = INFINITY;
    for (float x : with_nan)
        if (!std::isnan(x)) lo = std::min(lo, x);
    ASSERT_EQ(lo, -2.5f);
    for (int i = 0; i < 8; ++i) {
        const float expect = std::isnan(with_nan[size_t(i)]) ? lo : with_nan[size_t(i)];
        EXPECT_EQ(v.value(i & 1, i >> 1 & 1, i >> 2), expect) << "voxel " << i;
    }
    EXPECT_EQ(v.data_range().min, -2.5f);
    EXPECT_EQ(v.data_range().max, 7.f);  // (9 was voxel 6, a NaN now)
}

TEST(IoMalformed, NanOnlyFloatNiftiIsRejected) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.datatype = 16;
    std::vector<float> vox(8, std::numeric_limits<float>::quiet_NaN());
    test::write_bytes(dir.file("allnan.nii"), test::nifti_bytes(spec, vox.data(), vox.size() * 4));
    expect_read_error(dir.file("allnan.nii"), {"voxel values", "NaN only"});
}

TEST(IoMalformed, NanBesideInfIsStillRejectedForTheInf) {
    ScratchDir dir;
    NiftiSpec spec;
    spec.datatype = 16;
    std::vector<float> vox(8, 1.f);
    vox[2] = std::numeric_limits<float>::quiet_NaN();
    vox[5] = std::numeric_limits<float>::infinity();  // voxel (1,0,1)
    test::write_bytes(dir.file("naninf.nii"), test::nifti_bytes(spec, vox.data(), vox.size() * 4));
    expect_read_error(dir.file("naninf.nii"), {"Inf", "(1,0,1)"});
}

TEST(IoMalformed, InfInFloatNrrdIsRejected) {
    ScratchDir dir;
    std::vector<float> vox(27, 2.f);
    vox[26] = std::numeric_limits<float>::infinity();
    std::string text = nrrd_header("float", "3 3 3");
    text.append(reinterpret_cast<const char*>(vox.data()), vox.size() * 4);
    test::write_text(dir.file("inf.nrrd"), text);
    expect_read_error(dir.file("inf.nrrd"), {"Inf", "(2,2,2)"});
}

TEST(IoMalformed, NanInDoubleNrrdReadsAsTheMinimumAfterConversion) {
    ScratchDir dir;
    std::vector<double> vox(27, 2.0);
    vox[0] = std::numeric_limits<double>::quiet_NaN();
    std::string text = nrrd_header("double", "3 3 3");
    text.append(reinterpret_cast<const char*>(vox.data()), vox.size() * 8);
    test::write_text(dir.file("nan64.nrrd"), text);
    const Volume v = read_volume(dir.file("nan64.nrrd"));  // NaN is background, as in NIfTI
    EXPECT_EQ(v.nan_voxels, 1u);
    EXPECT_EQ(v.value(0, 0, 0), 2.f);
}

// ---------------------------------------------------------------------------------------------
// Conversions through the ITK path (positive cases next to the failures they border)

TEST(IoMalformed, NrrdTypeConversionsAreExact) {
    ScratchDir dir;
    {
        std::vector<int8_t> v(8);
        for (int i = 0; i < 8; ++i) v[i] = int8_t(-100 + 30 * i);
        std::string text = nrrd_header("int8", "2 2 2");
        text.append(reinterpret_cast<const char*>(v.data()), v.size());
        test::write_text(dir.file("i8.nrrd"), text);
        const Volume r = read_volume(dir.file("i8.nrrd"));
        ASSERT_EQ(r.type(), VoxelType::Int16);
        for (int i = 0; i < 8; ++i) EXPECT_EQ(r.data_as<int16_t>()[i], v[i]);
    }
    {
        std::vector<uint32_t> v(8);
        for (int i = 0; i < 8; ++i) v[i] = uint32_t(1000000 * i);
        std::string text = nrrd_header("uint32", "2 2 2");
        text.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
        test::write_text(dir.file("u32.nrrd"), text);
        const Volume r = read_volume(dir.file("u32.nrrd"));
        ASSERT_EQ(r.type(), VoxelType::Float32);
        for (int i = 0; i < 8; ++i) EXPECT_EQ(r.data_as<float>()[i], float(v[i]));
    }
}

TEST(IoMalformed, MetaImageWithNegativeNDimsFailsFast) {
    // MetaIO alone would try to read ~4 billion numbers for a 9-element field.
    ScratchDir dir;
    test::write_text(dir.file("neg.mha"),
                     "ObjectType = Image\nNDims = -3\nTransformMatrix = 1 0 0 0 1 0 0 0 1\n"
                     "DimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n"
                     "12345678");
    expect_read_error(dir.file("neg.mha"), {"NDims"});
}

// Random damage to small valid files: every outcome is a volume or one lacuna::Error line.
TEST(IoMalformed, SurvivesRandomByteDamageInEveryFormat) {
    ScratchDir dir;
    Volume v = test::pattern_volume({6, 5, 4}, VoxelType::Int16);
    const std::vector<std::string> names = {"a.nii", "a.nii.gz", "a.nrrd",
                                            "a.mha", "b.nhdr",   "c.mhd"};
    for (const auto& n : names) write_volume(dir.file(n), v);
    std::mt19937 rng(20240601);
    int errors = 0;
    for (const auto& n : names) {
        const std::vector<uint8_t> original = test::file_bytes(dir.file(n));
        const bool gz = n.find(".gz") != std::string::npos;
        for (int it = 0; it < 150; ++it) {
            std::vector<uint8_t> b = original;
            const size_t limit = gz ? b.size() : std::min<size_t>(b.size(), 600);
            for (int k = 0, flips = 1 + int(rng() % 4); k < flips && !b.empty(); ++k) {
                const size_t pos = rng() % std::min(limit, b.size());
                switch (rng() % 4) {
                    case 0:
                        b[pos] = uint8_t(rng());
                        break;
                    case 1:
                        b[pos] = uint8_t("0123456789 -\n"[rng() % 13]);
                        break;
                    case 2:
                        b[pos] ^= uint8_t(1u << (rng() % 8));
                        break;
                    default:
                        b.resize(pos);
                        break;
                }
            }
            // A fresh name each time: truncating a file can wait for writeback (ext4).
            const std::string path = dir.file("m" + std::to_string(it) + "_" + n);
            test::write_bytes(path, b);
            try {
                read_volume(path);
            } catch (const Error& e) {
                ++errors;
                EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
            }
            std::filesystem::remove(path);
        }
    }
    EXPECT_GT(errors, 100);
}

// Nothing above may print: ITK, MetaIO, NrrdIO and GDCM output is captured or silenced.
TEST(IoMalformed, FailuresPrintNothingToStderr) {
    ScratchDir dir;
    test::write_text(dir.file("short.mha"),
                     "ObjectType = Image\nNDims = 3\nDimSize = 16 16 16\nElementType = MET_SHORT\n"
                     "ElementDataFile = LOCAL\nabc");
    test::write_text(dir.file("short.nrrd"), nrrd_header("uint8", "16 16 16") + "abc");
    std::filesystem::create_directory(dir.path() / "junk");
    test::write_text(dir.file("junk/a.dcm"), "not dicom");
    ::testing::internal::CaptureStderr();
    for (const char* name : {"short.mha", "short.nrrd", "junk"})
        EXPECT_THROW(read_volume(dir.file(name)), Error);
    const std::string printed = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(printed, "");
}

}  // namespace
}  // namespace lacuna
