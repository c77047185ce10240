// The heap a space holds follows its contacts, not their high-water mark: the pyramid's
// bytes per body after its drop, and contact arrays given back when a pile comes apart
// (api/memory_report.hpp counts capacities, so the numbers are the same on every run).
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>

#include <gtest/gtest.h>

#include <string>

#include "api/memory_report.hpp"
#include "api/space_internals.hpp"
#include "solver/constraints.hpp"

using namespace spindle;

namespace {

// Jolt's pyramid (configs/scenes/pyramid.toml, 1240 boxes) dropped and landed.
struct Pyramid {
    SceneDesc scene = load_scene(std::string(SPINDLE_SOURCE_DIR) + "/configs/scenes/pyramid.toml");
    Space space{scene.settings};
    std::vector<BodyHandle> bodies = build(scene, space);

    explicit Pyramid(int steps) {
        for (int i = 0; i < steps; ++i) space.update();
    }
    double bytes_per_body() const {
        return static_cast<double>(memory_report(space).total()) / static_cast<double>(scene.dynamic_body_count());
    }
};

constexpr int kLanded = 300;   // landed after about 60 steps; bench_engine times 300 from the drop
constexpr int kSettled = 100;  // enough to have every contact (fewer steps: the sanitizer builds are slow)

}  // namespace

TEST(Memory, PyramidAfterItsDropHoldsUnderFifteenKilobytesPerBody) {
    const Pyramid pyramid(kLanded);
    // 21.1 KB per body before issue 19: the contact array doubled for a few new contacts,
    // and each point kept its anchors and its step's push.
    EXPECT_LT(pyramid.bytes_per_body(), 15'000);
    const World& world = SpaceInternals::world(pyramid.space);
    EXPECT_LE(world.contacts.capacity(), world.contacts.size() + world.contacts.size() / 2 + 64);
}

TEST(Memory, ContactArraysAreGivenBackWhenThePileComesApart) {
    Pyramid pyramid(kSettled);
    const World& world = SpaceInternals::world(pyramid.space);
    const std::size_t landed = world.contacts.size();
    ASSERT_GT(landed, 8000u);
    // All but the bottom layer's boxes gone: a tenth of the contacts are left.
    for (std::size_t i = 1 + 225; i < pyramid.bodies.size(); ++i) pyramid.space.destroy_body(pyramid.bodies[i]);
    pyramid.space.update();
    EXPECT_LT(world.contacts.size(), landed / 4);
    EXPECT_LE(world.contacts.capacity(), world.contacts.size() + world.contacts.size() / 2 + 64);
    EXPECT_LE(world.solver->wide.capacity(), world.solver->wide.size() + world.solver->wide.size() / 2 + 64);
}
