// Bricks read by file offset (src/io/brick_read.h) against brute force: the brick cut out of the
// whole volume read_volume reads, voxel for voxel, with the same geometry, for every format whose
// voxels lie at an offset and every stored type; compressed files are refused (read whole);
// truncated files fail from the header. And the visible-cell tree built from slabs
// (decompose_visible_slabs) against the tree of the whole volume (decompose_visible).
#include "io/brick_read.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "dist/brick_io.h"
#include "dist/decomposition.h"
#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/synthetic.h"

namespace lacuna::dist {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
    static const fs::path d = [] {
        fs::path p =
            fs::temp_directory_path() / ("lacuna_brick_read_" + std::to_string(::getpid()));
        fs::create_directories(p);
        return p;
    }();
    return d;
}

Volume shells(VoxelType t) {
    SyntheticOptions o;
    o.dims = {23, 17, 19};
    o.type = t;
    o.threads = 1;
    Volume v = generate(SyntheticKind::SphereShells, o);
    // An oblique, shifted frame, so the geometry the header gives is checked too.
    v.spacing = {0.8, 1.1, 1.3};
    v.origin = {4.5, -2.0, 7.25};
    const double d[9] = {0.8, -0.6, 0, 0.6, 0.8, 0, 0, 0, 1};
    std::copy_n(d, 9, v.direction);
    return v;
}

// Every voxel of the brick is the whole volume's at offset + (i, j, k), bit for bit (NaN too).
void expect_brick(const Volume& whole, const Volume& b, Vec3i off, const std::string& what) {
    ASSERT_EQ(b.type(), whole.type()) << what;
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(b.spacing[a], whole.spacing[a]) << what;
        EXPECT_EQ(b.origin[a], whole.origin[a]) << what;
    }
    for (int e = 0; e < 9; ++e) EXPECT_EQ(b.direction[e], whole.direction[e]) << what;
    const size_t vs = voxel_size(b.type());
    size_t bad = 0;
    for (int k = 0; k < b.dims().z; ++k)
        for (int j = 0; j < b.dims().y; ++j)
            for (int i = 0; i < b.dims().x; ++i)
                bad += std::memcmp(static_cast<const char*>(b.data()) + b.index(i, j, k) * vs,
                                   static_cast<const char*>(whole.data()) +
                                       whole.index(off.x + i, off.y + j, off.z + k) * vs,
                                   vs) != 0;
    EXPECT_EQ(bad, 0u) << what;
}

// For each file: every brick of 1..5 voxel-balanced ranks, and one brick spanning x and y (read
// in whole planes).
void check_file(const fs::path& p, const ReadOptions& ro = {}) {
    const Volume whole = read_volume(p.string(), ro);
    const std::optional<io::BrickFile> f = io::open_brick_file(p.string(), ro);
    ASSERT_TRUE(f) << p;
    EXPECT_EQ(f->header.data(), nullptr);
    EXPECT_EQ(f->header.dims(), whole.dims()) << p;
    for (int n = 1; n <= 5; ++n) {
        const Decomposition d = decompose_voxels(whole.dims(), n);
        for (int r = 0; r < n; ++r) {
            const Vec3i off = ownership(d, r).offset;
            Volume b = io::read_brick(*f, off, brick_voxels(d, r), ro.max_memory);
            expect_brick(whole, b, off,
                         p.string() + " rank " + std::to_string(r) + "/" + std::to_string(n));
        }
    }
    const Vec3i d = whole.dims();
    expect_brick(whole, io::read_brick(*f, {0, 0, 3}, {d.x, d.y, 5}, ro.max_memory), {0, 0, 3},
                 p.string() + " planes");
}

TEST(BrickRead, EveryOffsetFormatEqualsTheWholeVolumesBrick) {
    const struct {
        VoxelType type;
        const char* ext;
    } cases[] = {{VoxelType::UInt16, ".nrrd"}, {VoxelType::Int16, ".nhdr"},
                 {VoxelType::Float32, ".mha"}, {VoxelType::UInt8, ".mhd"},
                 {VoxelType::Int16, ".nii"},   {VoxelType::Float32, ".nii"}};
    int n = 0;
    for (const auto& c : cases) {
        const fs::path p = temp_dir() / ("v" + std::to_string(n++) + c.ext);
        write_volume(p.string(), shells(c.type));
        check_file(p);
    }
}

// Raw files in either byte order, float too: the other byte order is swapped as read_volume
// swaps it.
TEST(BrickRead, RawFilesInEitherByteOrder) {
    for (VoxelType t :
         {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16, VoxelType::Float32}) {
        const Volume v = shells(t);
        const std::string name = "r_23x17x19_" + to_string(t);
        const fs::path le = temp_dir() / (name + ".raw"), be = temp_dir() / (name + "_be.raw");
        write_volume(le.string(), v);
        std::string bytes(static_cast<const char*>(v.data()), v.bytes());
        const size_t vs = voxel_size(t);
        for (size_t i = 0; i < bytes.size(); i += vs) std::reverse(&bytes[i], &bytes[i] + vs);
        std::ofstream(be, std::ios::binary) << bytes;
        check_file(le);
        check_file(be);
    }
}

// NaN voxels come through as NaN (the caller replaces them by the whole volume's smallest value,
// as read_volume does, brick_io.h): each brick, replaced by that value, is read_volume's brick.
TEST(BrickRead, NanVoxelsBecomeTheWholeVolumesSmallestValue) {
    Volume v = shells(VoxelType::Float32);
    float* p = v.data_as<float>();
    for (size_t i = 0; i < v.voxel_count(); i += 7) p[i] = NAN;
    const fs::path f = temp_dir() / "nan_23x17x19_float32.raw";
    write_volume(f.string(), v);
    const Volume whole = read_volume(f.string());
    ASSERT_GT(whole.nan_voxels, 0u);
    const auto bf = io::open_brick_file(f.string(), {});
    ASSERT_TRUE(bf);
    const Decomposition d = decompose_voxels(whole.dims(), 4);
    float lo = INFINITY, hi = -INFINITY;
    std::vector<Volume> bricks;
    for (int r = 0; r < 4; ++r) {
        bricks.push_back(io::read_brick(*bf, ownership(d, r).offset, brick_voxels(d, r), {}));
        float a, b;
        finite_minmax(bricks.back(), a, b);
        lo = std::min(lo, a), hi = std::max(hi, b);
    }
    EXPECT_EQ(lo, whole.data_range().min);
    EXPECT_EQ(hi, whole.data_range().max);
    const ValueRange vis = default_vis_range(lo, hi);
    EXPECT_EQ(vis.min, whole.vis_range().min);
    EXPECT_EQ(vis.max, whole.vis_range().max);
    for (int r = 0; r < 4; ++r) {
        replace_nan(bricks[size_t(r)], lo);
        expect_brick(whole, bricks[size_t(r)], ownership(d, r).offset, "NaN brick");
    }
}

TEST(BrickRead, CompressedFilesAreReadWhole) {
    const fs::path p = temp_dir() / "c.nii.gz";
    write_volume(p.string(), shells(VoxelType::Int16));
    EXPECT_FALSE(io::open_brick_file(p.string(), {}));
}

// A file shorter than its header says fails from the header, before a voxel is read, with
// read_volume's own message.
TEST(BrickRead, TruncatedFilesFailFromTheHeader) {
    int n = 0;
    for (const char* ext : {".nrrd", ".mha", ".nii", ".raw"}) {
        const fs::path p = temp_dir() / ("t" + std::to_string(n++) + "_23x17x19_uint16" + ext);
        write_volume(p.string(), shells(VoxelType::UInt16));
        fs::resize_file(p, fs::file_size(p) - 100);
        std::string whole, brick;
        try {
            read_volume(p.string());
        } catch (const Error& e) {
            whole = e.what();
        }
        try {
            io::open_brick_file(p.string(), {});
        } catch (const Error& e) {
            brick = e.what();
        }
        EXPECT_FALSE(whole.empty()) << p;
        EXPECT_EQ(brick, whole) << p;
    }
}

// --max-memory applies to the brick: a budget below the brick's bytes refuses it, one above
// reads it (though the whole volume would not fit).
TEST(BrickRead, MemoryBudgetAppliesToTheBrick) {
    const fs::path p = temp_dir() / "budget.nrrd";
    write_volume(p.string(), shells(VoxelType::UInt16));
    const auto f = io::open_brick_file(p.string(), {});
    ASSERT_TRUE(f);
    MemoryBudget small{uint64_t(23 * 17 * 5 * 2 - 1), "--max-memory"};
    EXPECT_THROW(io::read_brick(*f, {0, 0, 0}, {23, 17, 5}, small), Error);
    small.bytes += 1;
    EXPECT_NO_THROW(io::read_brick(*f, {0, 0, 0}, {23, 17, 5}, small));
    EXPECT_LT(small.bytes, f->header.voxel_count() * 2);
}

// The visible tree from slabs (each slab's own table, the counts summed) is the whole volume's
// tree: the slabs partition the cells, so every box's count is the sum of its parts.
TEST(BrickRead, VisibleTreeFromSlabsIsTheWholeVolumesTree) {
    TransferFunction tf;
    tf.name = "test";
    tf.color = {{0.0, 1.f, 1.f, 1.f}, {1.0, 1.f, 1.f, 1.f}};
    tf.opacity = {{0.0, 0.f}, {0.55, 0.f}, {0.6, 0.7f}, {0.7, 0.f}, {1.0, 0.f}};
    for (VoxelType t : {VoxelType::UInt8, VoxelType::UInt16}) {
        SyntheticOptions o;
        o.dims = {40, 36, 44};
        o.type = t;
        o.threads = 1;
        const Volume whole = generate(SyntheticKind::Tree, o);  // lopsided: trees differ
        const TransferLut lut = discretise(tf, whole.vis_range());
        int differ = 0;
        for (int n : {2, 3, 4, 7}) {
            const Decomposition want = decompose_visible(whole, lut, n, 1);
            const Decomposition slabs = decompose_voxels(whole.dims(), n);
            std::vector<SlabCounts> counts;
            for (int r = 0; r < n; ++r) {
                Volume s = crop_brick(whole, ownership(slabs, r).offset, brick_voxels(slabs, r));
                counts.emplace_back(s, ownership(slabs, r).offset, slabs.bricks[size_t(r)], lut, 1);
            }
            // decompose_visible_slabs' weight with the ranks' allreduce done here: every slab's
            // count of the box, summed (tests/dist/mpi/ runs it over MPI).
            const Decomposition all = decompose(whole.dims(), n, [&](const CellBox& b) {
                uint64_t s = 0;
                for (const SlabCounts& c : counts) s += c.count(b);
                return double(s);
            });
            EXPECT_EQ(to_string(all), to_string(want)) << n << " ranks";
            differ += to_string(all) != to_string(slabs);
        }
        EXPECT_GT(differ, 0) << "every visible tree is the voxel tree: the test shows nothing";
    }
}

}  // namespace
}  // namespace lacuna::dist
