// PNG output (atomic) and input, and the heat map colour ramp.
#include <gtest/gtest.h>
#include <unistd.h>

#include "io/io_test_util.h"
#include "lacuna/image.h"

namespace lacuna {
namespace {

using test::ScratchDir;

Image gradient(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            uint8_t* p = img.pixel(x, y);
            p[0] = uint8_t(x * 255 / (w - 1));
            p[1] = uint8_t(y * 255 / (h - 1));
            p[2] = uint8_t((x * 7 + y * 13) & 0xff);
            p[3] = uint8_t(x % 2 ? 255 : 128);
        }
    return img;
}

TEST(Png, RoundTripsRgbaExactly) {
    ScratchDir dir;
    const Image img = gradient(37, 23);
    write_png(dir.file("g.png"), img);
    const Image back = read_png(dir.file("g.png"));
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.rgba, img.rgba);
    EXPECT_EQ(dir.names(), std::vector<std::string>{"g.png"});
}

TEST(Png, OverwritesAnExistingFileAtomically) {
    ScratchDir dir;
    write_png(dir.file("o.png"), gradient(4, 4));
    const Image second = gradient(9, 5);
    write_png(dir.file("o.png"), second);
    EXPECT_EQ(read_png(dir.file("o.png")).rgba, second.rgba);
    EXPECT_EQ(dir.names(), std::vector<std::string>{"o.png"});
}

TEST(Png, MissingDirectoryThrowsOutputErrorAndLeavesNoFile) {
    ScratchDir dir;
    const std::string path = dir.file("no/such/dir/out.png");
    const std::string msg = test::error_of([&] { write_png(path, gradient(4, 4)); });
    EXPECT_EQ(msg.rfind(path + ": output: cannot write", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
    EXPECT_TRUE(dir.names().empty());
}

TEST(Png, ParentThatIsAFileThrowsAndLeavesNoFile) {
    ScratchDir dir;
    test::write_text(dir.file("plain"), "x");
    const std::string path = dir.file("plain/out.png");
    const std::string msg = test::error_of([&] { write_png(path, gradient(4, 4)); });
    EXPECT_NE(msg.find("output: cannot write"), std::string::npos) << msg;
    EXPECT_EQ(dir.names(), std::vector<std::string>{"plain"});
}

TEST(Png, UnwritableDirectoryThrowsStrerrorAndLeavesNoFile) {
    ScratchDir dir;
    const auto locked = dir.path() / "locked";
    std::filesystem::create_directory(locked);
    std::filesystem::permissions(
        locked, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const std::string path = (locked / "out.png").string();
    EXPECT_TRUE(test::as_unprivileged([&] {
        return test::quiet_error_of([&] { write_png(path, gradient(4, 4)); }) ==
               path + ": output: cannot write: Permission denied";
    }));
    std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
    EXPECT_TRUE(std::filesystem::is_empty(locked));
}

TEST(Png, FailedRenameRemovesTheTemporary) {
    ScratchDir dir;
    std::filesystem::create_directory(dir.path() / "taken.png");
    const std::string msg =
        test::error_of([&] { write_png(dir.file("taken.png"), gradient(4, 4)); });
    EXPECT_NE(msg.find("taken.png: output: cannot write"), std::string::npos) << msg;
    EXPECT_EQ(dir.names(), std::vector<std::string>{"taken.png"});
}

TEST(Png, RejectsInconsistentImages) {
    ScratchDir dir;
    Image bad(4, 4);
    bad.rgba.resize(10);
    EXPECT_THROW(write_png(dir.file("bad.png"), bad), Error);
    EXPECT_THROW(write_png(dir.file("empty.png"), Image{}), Error);
    EXPECT_TRUE(dir.names().empty());
}

TEST(Png, ReadRejectsNonPngAndTruncatedFiles) {
    ScratchDir dir;
    test::write_text(dir.file("text.png"), "definitely not a png");
    const std::string msg = test::error_of([&] { read_png(dir.file("text.png")); });
    EXPECT_NE(msg.find("text.png"), std::string::npos) << msg;
    write_png(dir.file("full.png"), gradient(64, 64));
    auto bytes = test::file_bytes(dir.file("full.png"));
    bytes.resize(bytes.size() / 2);
    test::write_bytes(dir.file("half.png"), bytes);
    const std::string msg2 = test::error_of([&] { read_png(dir.file("half.png")); });
    EXPECT_NE(msg2.find("half.png"), std::string::npos) << msg2;
    EXPECT_EQ(msg2.find('\n'), std::string::npos) << msg2;
    EXPECT_THROW(read_png(dir.file("missing.png")), Error);
}

TEST(Heatmap, ZeroIsBlackAndMaximumIsWhite) {
    const std::vector<uint32_t> counts = {0, 5, 10, 20};
    const Image img = heatmap(counts, 2, 2);
    const uint8_t* zero = img.pixel(0, 0);
    const uint8_t* max = img.pixel(1, 1);
    EXPECT_EQ(zero[0] + zero[1] + zero[2], 0);
    EXPECT_EQ(max[0], 255);
    EXPECT_EQ(max[1], 255);
    EXPECT_EQ(max[2], 255);
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(img.rgba[i * 4 + 3], 255);
}

TEST(Heatmap, BrightnessGrowsWithCount) {
    std::vector<uint32_t> counts(256);
    for (uint32_t i = 0; i < 256; ++i) counts[i] = i;
    const Image img = heatmap(counts, 256, 1);
    // Perceived brightness (Rec. 709 luma) must never decrease along the ramp.
    double prev = -1;
    for (int x = 0; x < 256; ++x) {
        const uint8_t* p = img.pixel(x, 0);
        const double luma = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        EXPECT_GE(luma, prev - 0.5) << "at count " << x;
        prev = luma;
    }
}

TEST(Heatmap, ExplicitMaximumClampsLargerCounts) {
    const Image img = heatmap({0, 50, 100, 1000}, 4, 1, 100);
    const uint8_t* at_max = img.pixel(2, 0);
    const uint8_t* above = img.pixel(3, 0);
    EXPECT_EQ(std::vector<uint8_t>(at_max, at_max + 4), std::vector<uint8_t>(above, above + 4));
    EXPECT_EQ(at_max[0], 255);
    const uint8_t* half = img.pixel(1, 0);
    EXPECT_LT(half[0] + half[1] + half[2], 3 * 255);
    EXPECT_GT(half[0] + half[1] + half[2], 0);
}

TEST(Heatmap, AllZeroCountsGiveABlackImage) {
    const Image img = heatmap(std::vector<uint32_t>(6, 0), 3, 2);
    for (size_t i = 0; i < 6; ++i) {
        EXPECT_EQ(img.rgba[i * 4 + 0], 0);
        EXPECT_EQ(img.rgba[i * 4 + 3], 255);
    }
}

TEST(Heatmap, RejectsMismatchedSize) {
    EXPECT_THROW(heatmap(std::vector<uint32_t>(5), 2, 2), Error);
}

}  // namespace
}  // namespace lacuna
