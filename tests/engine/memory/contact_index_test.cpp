// ContactIndex (stages/contact_index.hpp) against std::unordered_map: inserts, repeated
// inserts and erases of pair keys, through growth and the backward shift of erase; and
// the same from jobs (claims, a rehash, erases split by runs).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include "../spatial/test_job_systems.hpp"
#include "stages/contact_index.hpp"

using namespace spindle;

namespace {

// A pair key of `bodies` bodies each touching some of the next `reach`, as a pile's are:
// many collide in the low bits.
std::uint64_t pile_key(std::mt19937_64& random, std::uint64_t bodies, std::uint64_t reach) {
    const std::uint64_t a = random() % bodies, b = a + 1 + random() % reach;
    return a << 32 | b;
}

}  // namespace

TEST(ContactIndex, AgreesWithAMapThroughInsertsAndErases) {
    ContactIndex index;
    std::unordered_map<std::uint64_t, std::uint32_t> reference;
    std::mt19937_64 random(7);
    auto key = [&] { return pile_key(random, 300, 40); };
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

// Keys claimed from jobs (three threads taking the ranges last to first), some of them there
// already, after the index grew by a rehash in jobs with keys in it: every key is found at
// the position it was given, and the keys there before keep theirs.
TEST(ContactIndex, KeysClaimedInJobsAfterARehashInJobs_AreAllFound) {
    test::ReverseThreadedJobSystem jobs(3);
    ContactIndex index;
    std::unordered_map<std::uint64_t, std::uint32_t> reference;
    std::mt19937_64 random(11);
    auto key = [&] { return pile_key(random, 20000, 40); };
    while (reference.size() < 20000) {
        const std::uint64_t k = key();
        const auto position = static_cast<std::uint32_t>(reference.size());
        if (reference.try_emplace(k, position).second) index.insert(k, position);
    }
    std::vector<std::uint64_t> keys;  // distinct: 30,000 new ones and every 4th old one
    std::unordered_map<std::uint64_t, std::uint32_t> added;
    while (added.size() < 30000) {
        const std::uint64_t k = key();
        if (reference.count(k) == 0 && added.try_emplace(k, 0).second) keys.push_back(k);
    }
    std::size_t old = 0;
    for (const auto& [k, position] : reference) {
        if (old++ % 4 == 0) keys.push_back(k);
    }
    std::shuffle(keys.begin(), keys.end(), random);
    const std::size_t slots_before = index.heap_bytes();
    index.reserve(reference.size() + keys.size(), &jobs);
    ASSERT_GT(index.heap_bytes(), slots_before);  // it grew
    std::vector<std::uint32_t> claimed(keys.size());
    std::atomic<std::size_t> count{0};
    jobs.parallel_for("claim", 0, static_cast<std::uint32_t>(keys.size()), 500,
                      [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
                          for (std::uint32_t k = lo; k < hi; ++k) {
                              claimed[k] = index.claim(keys[k]);
                              if (claimed[k] != ContactIndex::kNotClaimed) count.fetch_add(1);
                          }
                      });
    ASSERT_EQ(count.load(), added.size());
    index.add_claimed(count.load());
    for (std::size_t k = 0; k < keys.size(); ++k) {
        const bool is_new = added.count(keys[k]) != 0;
        ASSERT_EQ(claimed[k] != ContactIndex::kNotClaimed, is_new) << "key " << k;
        if (!is_new) continue;
        const auto position = static_cast<std::uint32_t>(1000000 + k);
        index.set_position_at(claimed[k], position);
        reference[keys[k]] = position;
    }
    ASSERT_EQ(index.size(), reference.size());
    for (const auto& [k, position] : reference) {
        const std::uint32_t* found = index.find(k);
        ASSERT_NE(found, nullptr) << "key " << (k >> 32) << ", " << (k & 0xffffffffu);
        ASSERT_EQ(*found, position);
    }
}

// Erases in jobs, split by runs of full slots, leave the index a map of the other keys:
// each erased key gone, the others at their positions, also where a run wraps past the
// last slot. The keys crowd a few thousand homes, so the runs are long.
TEST(ContactIndex, ErasedInJobs_TheOthersAreFoundAtTheirPositions) {
    test::ReverseThreadedJobSystem jobs(3);
    std::mt19937_64 random(5);
    for (int round = 0; round < 4; ++round) {
        ContactIndex index;
        std::vector<std::uint64_t> keys;
        std::unordered_map<std::uint64_t, std::uint32_t> reference;
        while (keys.size() < 30000) {
            const std::uint64_t k = pile_key(random, 3000, 60);
            if (!reference.try_emplace(k, static_cast<std::uint32_t>(keys.size())).second) continue;
            index.insert(k, static_cast<std::uint32_t>(keys.size()));
            keys.push_back(k);
        }
        std::vector<std::uint32_t> positions;
        for (std::uint32_t p = 0; p < keys.size(); ++p) {
            if (random() % 3 == 0) positions.push_back(p);
        }
        index.erase_at(jobs, positions, keys);
        for (std::uint32_t p : positions) reference.erase(keys[p]);
        ASSERT_EQ(index.size(), reference.size()) << "round " << round;
        for (std::uint32_t p : positions) ASSERT_EQ(index.find(keys[p]), nullptr) << "round " << round;
        for (const auto& [k, position] : reference) {
            const std::uint32_t* found = index.find(k);
            ASSERT_NE(found, nullptr) << "round " << round;
            ASSERT_EQ(*found, position);
        }
    }
}
