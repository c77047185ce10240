// ContactIndex (stages/contact_index.hpp) against std::unordered_map: inserts, repeated
// inserts and erases of pair keys, through growth and the backward shift of erase.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <unordered_map>

#include "stages/contact_index.hpp"

using namespace spindle;

TEST(ContactIndex, AgreesWithAMapThroughInsertsAndErases) {
    ContactIndex index;
    std::unordered_map<std::uint64_t, std::uint32_t> reference;
    std::mt19937_64 random(7);
    // Pair keys of a few hundred bodies, as a pile's are: many collide in the low bits.
    auto key = [&] {
        const std::uint64_t a = random() % 300, b = a + 1 + random() % 40;
        return a << 32 | b;
    };
    for (int round = 0; round < 20000; ++round) {
        const std::uint64_t k = key();
        if (random() % 3 == 0) {
            index.erase(k);
            reference.erase(k);
        } else {
            const auto position = static_cast<std::uint32_t>(round);
            EXPECT_EQ(index.insert(k, position), reference.try_emplace(k, position).second);
        }
        ASSERT_EQ(index.size(), reference.size());
    }
    for (std::uint64_t a = 0; a < 300; ++a) {
        for (std::uint64_t b = a + 1; b <= a + 40; ++b) {
            const std::uint64_t k = a << 32 | b;
            const auto it = reference.find(k);
            const std::uint32_t* found = index.find(k);
            ASSERT_EQ(found != nullptr, it != reference.end()) << "key " << a << ", " << b;
            if (found) {
                EXPECT_EQ(*found, it->second);
            }
        }
    }
}

TEST(ContactIndex, FindsNothingWhenEmptyAndAfterErasingAll) {
    ContactIndex index;
    EXPECT_EQ(index.find(1), nullptr);
    index.erase(1);
    for (std::uint32_t i = 0; i < 1000; ++i) EXPECT_TRUE(index.insert(std::uint64_t{i} << 32 | (i + 1), i));
    EXPECT_FALSE(index.insert(std::uint64_t{5} << 32 | 6, 99));
    EXPECT_EQ(*index.find(std::uint64_t{5} << 32 | 6), 5u);
    for (std::uint32_t i = 0; i < 1000; ++i) index.erase(std::uint64_t{i} << 32 | (i + 1));
    EXPECT_EQ(index.size(), 0u);
    for (std::uint32_t i = 0; i < 1000; ++i) EXPECT_EQ(index.find(std::uint64_t{i} << 32 | (i + 1)), nullptr);
}
