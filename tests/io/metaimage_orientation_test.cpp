// MetaImage AnatomicalOrientation (issue 14, docs/formats.md "World frame"). MetaIO's letters name
// the side each index axis comes FROM: "RAI" is x from right to left, y from anterior to
// posterior, z from inferior to superior, which is LPS+ identity, and ITK writes "RAI" for it.
// ITK reads only TransformMatrix (identity when absent), so a file that states its axes by the
// letters alone read as LPS identity whatever they said. Here: without a TransformMatrix the
// letters define the axes; with one, TransformMatrix wins (every ITK-based tool reads only it, and
// writers exist that put "RAI" beside any matrix) and `lacuna info` says they disagree.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "io/io_test_util.h"
#include "lacuna/io.h"
#include "lacuna/orientation.h"

namespace lacuna {
namespace {

// The RAS direction an index axis points toward when MetaIO says it comes from `letter`: the
// opposite side (R -> toward L = -x in RAS; I -> toward S = +z). Written out by hand, not
// derived from the reader's table.
Vec3d ras_toward_from(char letter) {
    switch (letter) {
        case 'R':
            return {-1, 0, 0};
        case 'L':
            return {1, 0, 0};
        case 'A':
            return {0, -1, 0};
        case 'P':
            return {0, 1, 0};
        case 'I':
            return {0, 0, 1};
        case 'S':
            return {0, 0, -1};
    }
    return {0, 0, 0};
}
char opposite(char c) {
    const std::string from = "RLAPIS", to = "LRPASI";
    return to[from.find(c)];
}

// A 3x4x5 uint8 MetaImage with voxel data attached; `extra` are header lines before the data.
std::string write_mha(const test::ScratchDir& dir, const std::string& name,
                      const std::string& extra) {
    std::string text =
        "ObjectType = Image\nNDims = 3\nDimSize = 3 4 5\nElementSpacing = 1 2 3\n"
        "Offset = 10 20 30\n" +
        extra + "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n";
    for (int i = 0; i < 60; ++i) text += char(i);
    const std::string path = dir.file(name);
    test::write_text(path, text);
    return path;
}

// Every one of the 48 signed axis permutations, as MetaIO letters: the index axes' RAS
// directions follow the letters, the origin is Offset (LPS), and ITK's own writer, given that
// direction, writes the same letters (so the convention is ITK's, not ours).
TEST(MetaImageOrientation, WithoutATransformMatrixTheLettersDefineTheAxes) {
    const test::ScratchDir dir;
    const std::array<std::string, 3> pairs = {"RL", "AP", "IS"};
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int files = 0;
    for (const auto& p : perms)
        for (int signs = 0; signs < 8; ++signs) {
            std::string code;
            for (int a = 0; a < 3; ++a) code += pairs[size_t(p[a])][size_t((signs >> a) & 1)];
            SCOPED_TRACE(code);
            const std::string path =
                write_mha(dir, code + ".mha", "AnatomicalOrientation = " + code + "\n");
            const Volume v = read_volume(path);
            const Affine a = index_to_world(v);
            std::string toward;
            for (int c = 0; c < 3; ++c) {
                const Vec3d d = ras_toward_from(code[size_t(c)]);
                for (int r = 0; r < 3; ++r) EXPECT_EQ(a.m[r][c], d[r] * v.spacing[c]) << r << c;
                toward += opposite(code[size_t(c)]);
            }
            EXPECT_EQ(a.t[0], -10.0);  // Offset is LPS, as with a TransformMatrix
            EXPECT_EQ(a.t[1], -20.0);
            EXPECT_EQ(a.t[2], 30.0);
            EXPECT_EQ(orientation_code(v), toward);  // nibabel's letters: where each axis points
            EXPECT_NE(v.geometry_source.find("AnatomicalOrientation " + code), std::string::npos)
                << v.geometry_source;
            // ITK's writer: the same direction gives the same letters (and a TransformMatrix).
            write_volume(dir.file("itk.mha"), v);
            const std::vector<uint8_t> b = test::file_bytes(dir.file("itk.mha"));
            const std::string header(b.begin(), b.end());
            EXPECT_NE(header.find("AnatomicalOrientation = " + code + "\n"), std::string::npos)
                << header.substr(0, 400);
            const Volume back = read_volume(dir.file("itk.mha"));
            for (int i = 0; i < 9; ++i) EXPECT_EQ(back.direction[i], v.direction[i]);
            EXPECT_EQ(back.geometry_source.find("disagrees"), std::string::npos);
            ++files;
        }
    EXPECT_EQ(files, 48);
    // "???" (MetaIO's unknown) and no field at all: TransformMatrix's default, LPS identity.
    for (const std::string extra : {"AnatomicalOrientation = ???\n", ""}) {
        const Volume v = read_volume(write_mha(dir, "unknown.mha", extra));
        EXPECT_EQ(orientation_code(v), "LPS") << extra;
    }
}

// A TransformMatrix beside letters that say otherwise: the matrix is the geometry (as in ITK),
// and the disagreement is in `lacuna info`'s geometry line.
TEST(MetaImageOrientation, ATransformMatrixWinsOverDisagreeingLetters) {
    const test::ScratchDir dir;
    // Rows are the index axes' LPS directions: i toward the patient's right, j anterior, k up:
    // RAS, which MetaIO letters call LPI.
    const std::string matrix = "TransformMatrix = -1 0 0 0 -1 0 0 0 1\n";
    const Volume agree =
        read_volume(write_mha(dir, "agree.mha", matrix + "AnatomicalOrientation = LPI\n"));
    const Volume disagree =
        read_volume(write_mha(dir, "disagree.mha", matrix + "AnatomicalOrientation = RAI\n"));
    for (const Volume* v : {&agree, &disagree}) {
        EXPECT_EQ(orientation_code(*v), "RAS");
        const double ras_in_lps[9] = {-1, 0, 0, 0, -1, 0, 0, 0, 1};
        for (int i = 0; i < 9; ++i) EXPECT_EQ(v->direction[i], ras_in_lps[i]);
    }
    EXPECT_EQ(agree.geometry_source.find("disagrees"), std::string::npos) << agree.geometry_source;
    EXPECT_NE(disagree.geometry_source.find(
                  "AnatomicalOrientation RAI disagrees with TransformMatrix (LPI"),
              std::string::npos)
        << disagree.geometry_source;
    EXPECT_NE(disagree.geometry_source.find("TransformMatrix wins"), std::string::npos);
    // MetaIO's synonyms of TransformMatrix count as one.
    for (const char* key : {"Rotation", "Orientation"}) {
        const Volume v = read_volume(
            write_mha(dir, std::string(key) + ".mha",
                      std::string(key) + " = -1 0 0 0 -1 0 0 0 1\nAnatomicalOrientation = RAI\n"));
        EXPECT_EQ(orientation_code(v), "RAS") << key;
    }
}

// Letters that name no rigid axis set are one line naming the file and the field.
TEST(MetaImageOrientation, BadLettersAreOneLineNamingTheField) {
    const test::ScratchDir dir;
    for (const char* bad : {"RRA", "RAX", "RA", "rai", "R?I", "SIA"}) {
        const std::string path =
            write_mha(dir, "bad.mha", std::string("AnatomicalOrientation = ") + bad + "\n");
        const std::string msg = test::error_of([&] { read_volume(path); });
        EXPECT_NE(msg.find("bad.mha: AnatomicalOrientation: expected three letters"),
                  std::string::npos)
            << bad << ": " << msg;
        EXPECT_NE(msg.find(std::string("got '") + bad + "'"), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
}

}  // namespace
}  // namespace lacuna
