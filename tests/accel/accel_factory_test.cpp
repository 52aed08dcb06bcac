// The closed set of structures (include/lacuna/accel.h, src/accel/accel.cpp): names, the one
// parser, the factory and its option checks, and the dispatch in src/accel/accel_impl.h.
#include <gtest/gtest.h>

#include <set>
#include <typeinfo>

#include "accel/accel_impl.h"
#include "accel_test_util.h"
#include "lacuna/error.h"

namespace lacuna {
namespace {

using namespace accel_test;

TEST(AccelFactory, MakesEveryKindWithItsOwnType) {
    Rng rng{71};
    const Volume v = random_volume(VoxelType::Int16, {11, 6, 9}, rng);
    const std::vector<AccelKind> kinds = all_accel_kinds();
    ASSERT_FALSE(kinds.empty());
    EXPECT_EQ(kinds.front(), AccelKind::None) << "None first: the reference";
    for (AccelKind k : kinds) {
        const auto a = make_accel(k, v);
        ASSERT_NE(a, nullptr) << to_string(k);
        EXPECT_EQ(a->kind(), k) << to_string(k);
        a->set_transfer_function(random_lut(v.vis_range(), kDefaultLutSize, rng));
        const Accel& base = *a;
        const std::type_info& dynamic = typeid(base);
        // The structures this file knows; a newer kind only has to agree with visit_accel.
        const std::type_info* expected =
            k == AccelKind::None                                       ? &typeid(NoAccel)
            : k == AccelKind::MinMax || k == AccelKind::MinMaxInterval ? &typeid(MinMaxOctree)
            : k == AccelKind::Bitfield                                 ? &typeid(BitfieldOctree)
            : k == AccelKind::Boolean                                  ? &typeid(BooleanOctree)
            : k == AccelKind::Distance || k == AccelKind::Chebyshev    ? &typeid(DistanceMap)
                                                                       : nullptr;
        if (expected) EXPECT_EQ(dynamic, *expected) << to_string(k);
        // visit_accel hands the renderers the same concrete type.
        const std::type_info& visited =
            visit_accel(*a, [](const auto& s) -> const std::type_info& { return typeid(s); });
        EXPECT_EQ(visited, dynamic) << to_string(k);
        if (k != AccelKind::None) {
            EXPECT_GT(a->stats().nodes, 0u) << to_string(k);
            EXPECT_GT(a->stats().bytes, 0u) << to_string(k);
        }
    }
}

TEST(AccelFactory, ParseAccelRoundTripsEveryName) {
    const std::vector<std::string> names = accel_names();
    const std::vector<AccelKind> kinds = all_accel_kinds();
    ASSERT_EQ(names.size(), kinds.size());
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size())
        << "duplicate names";
    for (size_t i = 0; i < names.size(); ++i) {
        EXPECT_EQ(parse_accel(names[i]), kinds[i]) << names[i];
        EXPECT_EQ(to_string(kinds[i]), names[i]);
        EXPECT_EQ(parse_accel(to_string(kinds[i])), kinds[i]);
    }
    for (const char* n : {"none", "minmax", "bitfield", "boolean", "distance", "chebyshev"})
        EXPECT_NO_THROW(parse_accel(n)) << n;
}

TEST(AccelFactory, ParseAccelRejectsUnknownNamesListingTheValidOnes) {
    for (const char* bad : {"", "MinMax", "kd-tree", " none", "none ", "octree", "bitfield64"}) {
        try {
            parse_accel(bad);
            FAIL() << "'" << bad << "' was accepted";
        } catch (const Error& e) {
            const std::string msg = e.what();
            EXPECT_EQ(msg.rfind("frame: structure: ", 0), 0u) << msg;  // a field, not a flag
            EXPECT_NE(msg.find(std::string("'") + bad + "'"), std::string::npos) << msg;
            for (const std::string& name : accel_names())
                EXPECT_NE(msg.find(name), std::string::npos) << msg << " does not name " << name;
        }
    }
}

TEST(AccelFactory, InvalidOptionsThrowLacunaError) {
    Rng rng{72};
    const Volume v = random_volume(VoxelType::UInt8, {9, 9, 9}, rng);
    for (AccelKind k : {AccelKind::MinMax, AccelKind::Bitfield, AccelKind::Boolean})
        for (int leaf : {3, 0, 1, -4, 6, 128}) {
            AccelOptions o;
            o.leaf_cells = leaf;
            EXPECT_THROW(make_accel(k, v, o), Error) << to_string(k) << " leaf " << leaf;
        }
    for (int bits : {12, 0, 4, 7, 65, 256}) {
        AccelOptions o;
        o.bitfield_bits = bits;
        EXPECT_THROW(make_accel(AccelKind::Bitfield, v, o), Error) << "bits " << bits;
    }
    for (AccelKind k : {AccelKind::Distance, AccelKind::Chebyshev})
        for (int block : {0, -1, 65}) {
            AccelOptions o;
            o.distance_block = block;
            EXPECT_THROW(make_accel(k, v, o), Error) << to_string(k) << " distance block " << block;
        }
    // The valid extremes are accepted.
    for (int leaf : {2, 64}) {
        AccelOptions o;
        o.leaf_cells = leaf;
        EXPECT_NO_THROW(make_accel(AccelKind::MinMax, v, o)) << "leaf " << leaf;
    }
    for (int bits : {8, 16, 32, 64, 128}) {
        AccelOptions o;
        o.bitfield_bits = bits;
        EXPECT_NO_THROW(make_accel(AccelKind::Bitfield, v, o)) << "bits " << bits;
    }
    for (int block : {1, 64}) {
        AccelOptions o;
        o.distance_block = block;
        EXPECT_NO_THROW(make_accel(AccelKind::Distance, v, o)) << "distance block " << block;
    }
}

}  // namespace
}  // namespace lacuna
