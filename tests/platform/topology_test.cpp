#include <spindle/platform/error.hpp>
#include <spindle/platform/topology.hpp>

#include <gtest/gtest.h>

using spindle::Topology;

TEST(Topology, SyntheticXbox360HasThreeCoresOfTwoThreads) {
    const Topology t = Topology::from_synthetic("package:1 core:3 pu:2");
    ASSERT_EQ(t.pus().size(), 6u);
    ASSERT_EQ(t.cores().size(), 3u);
    EXPECT_EQ(t.package_count(), 1u);
    for (unsigned i = 0; i < 6; ++i) {
        EXPECT_EQ(t.pus()[i].logical, i);
        EXPECT_EQ(t.pus()[i].core, i / 2);
    }
    EXPECT_EQ(t.cores()[2].pus, (std::vector<unsigned>{4, 5}));
    EXPECT_FALSE(t.is_real());
}

TEST(Topology, SyntheticSmtMachineListsPackagesAndOsIndices) {
    const Topology t = Topology::from_synthetic("package:2 core:4 pu:2");
    ASSERT_EQ(t.pus().size(), 16u);
    EXPECT_EQ(t.cores().size(), 8u);
    EXPECT_EQ(t.package_count(), 2u);
    EXPECT_EQ(t.pus()[9].package, 1u);
    EXPECT_EQ(t.pus()[9].core, 4u);
    for (const auto& pu : t.pus()) EXPECT_LT(pu.os_index, 16u);
}

TEST(Topology, RejectsBrokenSyntheticDescription) {
    EXPECT_THROW(Topology::from_synthetic("package:1 banana:3"), spindle::Error);
}

TEST(Topology, RealMachineHasAtLeastOneThread) {
    const Topology t = Topology::from_system();
    EXPECT_TRUE(t.is_real());
    ASSERT_FALSE(t.pus().empty());
    EXPECT_FALSE(t.cores().empty());
    EXPECT_NE(t.summary().find("hardware thread"), std::string::npos);
}
