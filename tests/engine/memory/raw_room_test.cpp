// RawRoomVector (memory/huge_page_vector.hpp): a resize leaves the new elements' bytes as
// they were, so the solver's per-step arrays on it must be written whole before they are
// read in any step that grows them. Checked by growing them into room filled with bytes
// that read as NaN or as indices far out of range: a step must not see them.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "api/space_internals.hpp"
#include "memory/huge_page_vector.hpp"
#include "solver/constraints.hpp"
#include "static_bodies.hpp"

using namespace spindle;

namespace {

// Room for twice the array's elements and a few more (not so far above use that a step
// gives it back: stages/capacity.hpp), its bytes beyond them all `byte`.
template <typename T>
void fill_room_of(RawRoomVector<T>& v, unsigned char byte) {
    constexpr std::size_t kFew = 64;
    v.reserve(2 * v.size() + kFew);
    std::memset(static_cast<void*>(v.data() + v.size()), byte, (v.capacity() - v.size()) * sizeof(T));
}

void fill_solver_room(SolverScratch& scratch, unsigned char byte) {
    fill_room_of(scratch.bodies, byte);
    fill_room_of(scratch.push_velocities, byte);
    fill_room_of(scratch.gravity_scales, byte);
    fill_room_of(scratch.manifolds, byte);
    fill_room_of(scratch.colored_manifolds, byte);
    fill_room_of(scratch.wide, byte);
    fill_room_of(scratch.push_anchors, byte);
}

// A floor and a 4 x 4 block of resting cubes; more() drops a second, smaller block whose
// cubes overlap each other deeply (the push-out rows and their anchors run).
struct RoomScene {
    Space space;

    RoomScene() {
        test::add_static_box(space, Vec3(10, 1, 10), Vec3(0, -1, 0));
        for (int x = 0; x < 4; ++x) {
            for (int z = 0; z < 4; ++z) add_cube(Vec3(-2 + 1.1 * x, 0.5, -2 + 1.1 * z));
        }
    }
    void add_cube(const Vec3& at) {
        BodyDesc cube;
        cube.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        cube.position = at;
        space.create_body(cube);
    }
    void more() {
        for (int x = 0; x < 3; ++x) {
            for (int z = 0; z < 3; ++z) add_cube(Vec3(-2 + 0.8 * x, 1.5, -2 + 0.8 * z));
        }
    }
    SolverScratch& scratch() { return *SpaceInternals::world(space).solver; }
};

}  // namespace

TEST(RawRoom, ResizeKeepsTheRoomsBytesAndCopiesConstruct) {
    RawRoomVector<double> v(4, 1.5);
    v.reserve(16);
    std::memset(static_cast<void*>(v.data() + 4), 0x7f, 12 * sizeof(double));
    double pattern = 0;
    std::memset(&pattern, 0x7f, sizeof pattern);
    v.resize(16);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(v[i], 1.5);
    for (std::size_t i = 4; i < 16; ++i) EXPECT_EQ(std::memcmp(&v[i], &pattern, sizeof pattern), 0) << i;
    v.push_back(2.5);
    EXPECT_EQ(v.back(), 2.5);
    const RawRoomVector<double> copy = v;
    EXPECT_EQ(std::memcmp(copy.data(), v.data(), v.size() * sizeof(double)), 0);
}

// The arrays grow into their room on the step after more cubes come: with the room all
// 0xff bytes (NaN floats, -1 counts, indices far out of range) or all 0x5a bytes (large
// counts and indices), the steps are bitwise those of the same scene whose room is zeros.
TEST(RawRoom, SolverArraysGrownIntoDirtyRoomStepAsIntoZeros) {
    constexpr unsigned char kFills[] = {0xff, 0x5a};
    for (const unsigned char fill : kFills) {
        RoomScene clean, dirty;
        for (int i = 0; i < 3; ++i) {
            clean.space.update();
            dirty.space.update();
        }
        const std::size_t wide_before = dirty.scratch().wide.size();
        const std::size_t bodies_before = dirty.scratch().bodies.size();
        fill_solver_room(clean.scratch(), 0x00);
        fill_solver_room(dirty.scratch(), fill);
        const WideContact* wide = dirty.scratch().wide.data();
        const SolverBody* bodies = dirty.scratch().bodies.data();
        clean.more();
        dirty.more();
        for (int i = 0; i < 20; ++i) {
            clean.space.update();
            dirty.space.update();
            if (i == 0) {
                // Grown in place, into the filled room.
                EXPECT_GT(dirty.scratch().wide.size(), wide_before);
                EXPECT_GT(dirty.scratch().bodies.size(), bodies_before);
                EXPECT_EQ(dirty.scratch().wide.data(), wide);
                EXPECT_EQ(dirty.scratch().bodies.data(), bodies);
            }
            ASSERT_EQ(dirty.space.state_hash(), clean.space.state_hash()) << "fill " << int{fill} << ", step " << i;
        }
    }
}
