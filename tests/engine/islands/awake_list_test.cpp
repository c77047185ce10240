// The awake list (World::awake) after islands wake and sleep: ascending slot order and
// positions that match, whatever order the bodies woke or left in (engine internals).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "stages/stages.hpp"

using namespace spindle;

namespace {

constexpr std::uint32_t kSlots = 16;

// Bodies 3, 7 and 12 awake; islands 0 {9, 2, 14} and 1 {5, 0, 11} asleep; the rest static.
void build(World& world) {
    Bodies& b = world.bodies;
    b.type.assign(kSlots, MotionType::Static);
    b.awake_index.assign(kSlots, -1);
    b.sleep_time.assign(kSlots, 0);
    b.island.assign(kSlots, -1);
    const std::vector<std::vector<std::uint32_t>> islands = {{9, 2, 14}, {5, 0, 11}};
    world.sleeping_islands.resize(islands.size());
    for (std::size_t i = 0; i < islands.size(); ++i) {
        world.sleeping_islands[i].bodies = islands[i];
        for (std::uint32_t slot : islands[i]) {
            b.type[slot] = MotionType::Dynamic;
            b.island[slot] = static_cast<std::int32_t>(i);
        }
    }
    for (std::uint32_t slot : {3u, 7u, 12u}) {
        b.type[slot] = MotionType::Dynamic;
        set_awake(world, slot, true);
    }
    settle_awake(world);
}

// FNV-1a over the awake list and each listed body's recorded position.
std::uint64_t awake_hash(const World& world) {
    std::uint64_t hash = 1469598103934665603ull;
    auto mix = [&hash](std::uint64_t v) {
        for (int i = 0; i < 8; ++i) hash = (hash ^ ((v >> (8 * i)) & 0xffu)) * 1099511628211ull;
    };
    for (std::uint32_t slot : world.awake) {
        mix(slot);
        mix(static_cast<std::uint64_t>(world.bodies.awake_index[slot]));
    }
    return hash;
}

// Wakes island 0's body 14 and island 1's body 5 in the given order, with body 7 leaving
// and coming back and body 12 leaving between them, then settles once.
std::uint64_t wake_in_order(bool island_0_first) {
    World world;
    build(world);
    wake_body(world, island_0_first ? 14 : 5);
    set_awake(world, 7, false);
    set_awake(world, 12, false);
    set_awake(world, 7, true);
    wake_body(world, island_0_first ? 5 : 14);
    settle_awake(world);
    EXPECT_EQ(world.awake, (std::vector<std::uint32_t>{0, 2, 3, 5, 7, 9, 11, 14}));
    for (std::size_t k = 0; k < world.awake.size(); ++k) {
        EXPECT_EQ(world.bodies.awake_index[world.awake[k]], static_cast<std::int32_t>(k)) << "body " << world.awake[k];
    }
    EXPECT_EQ(world.bodies.awake_index[12], -1);
    return awake_hash(world);
}

}  // namespace

TEST(AwakeList, WakingInEitherOrderGivesTheSameList) { EXPECT_EQ(wake_in_order(true), wake_in_order(false)); }

TEST(AwakeList, SleepersLeaveAndTheRestKeepTheirOrder) {
    World world;
    build(world);
    wake_body(world, 2);
    settle_awake(world);
    for (std::uint32_t slot : {2u, 9u, 3u}) set_awake(world, slot, false);
    settle_awake(world);
    EXPECT_EQ(world.awake, (std::vector<std::uint32_t>{7, 12, 14}));
    for (std::size_t k = 0; k < world.awake.size(); ++k) {
        EXPECT_EQ(world.bodies.awake_index[world.awake[k]], static_cast<std::int32_t>(k));
    }
}
