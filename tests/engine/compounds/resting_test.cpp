// Compounds at rest: a dumbbell and a table on a plane, a box, a triangle mesh and on
// each other come to rest at the height their parts give, without drifting or turning,
// and fall asleep. A compound of one ball rolls exactly as the ball (its round part's
// radius reaches the solver and contact recycling per part).
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "compound_test_util.hpp"
#include "grid_mesh.hpp"

namespace spindle {
namespace {

using namespace test;

constexpr int kSettleSteps = 600;  // 10 s
// Soft contacts rest a little inside each other (the allowed slop and the load's share).
constexpr Real kRestDepth = 0.01;

BodyDesc body(const Shape& shape, const Vec3& position, MotionType type = MotionType::Dynamic) {
    BodyDesc d;
    d.type = type;
    d.shape = shape;
    d.position = position;
    return d;
}

BodyHandle add_plane(Space& space) {
    return space.create_body(body(Shape::plane(Vec3::UnitY(), 0), Vec3::Zero(), MotionType::Static));
}

// A flat square of 8 x 8 cells of 1 m on y = 0.
Shape floor_mesh() { return flat_grid_mesh(8, 1.0); }

// A drop of a few centimetres lands with some slide and turn (a single box dropped 10 cm
// slides 2 mm; a table on four separate leg manifolds up to 9 mm and 0.4 degrees).
constexpr Real kLandingSlide = 0.015;
constexpr Real kLandingTurn = 0.012;

// Steps until the body sleeps (at most kSettleSteps).
void step_until_asleep(Space& space, BodyHandle handle) {
    for (int i = 0; i < kSettleSteps && space.internal_is_awake(handle); ++i) space.update();
}

// Steps until the body sleeps or kSettleSteps pass; expects it asleep near where it
// started in x and z, at `height`, hardly turned from `orientation`.
void expect_rests(Space& space, BodyHandle handle, const Vec3& start, Real height, const Quat& orientation,
                  const char* what) {
    step_until_asleep(space, handle);
    const Vec3 p = space.position(handle);
    EXPECT_FALSE(space.internal_is_awake(handle)) << what << ": still awake after " << kSettleSteps << " steps";
    EXPECT_NEAR(p.y(), height, kRestDepth) << what;
    EXPECT_LT(Vec3(p.x() - start.x(), 0, p.z() - start.z()).norm(), kLandingSlide)
        << what << ": slid to " << p.transpose();
    EXPECT_LT(space.orientation(handle).angularDistance(orientation), kLandingTurn) << what << ": turned";
}

// With sleeping off, a compound placed touching the ground stays put: after a second to
// settle, ten more seconds move it less than 0.1 mm and turn it less than 0.001 rad.
void expect_no_drift(Space& space, BodyHandle handle, const char* what) {
    for (int i = 0; i < 60; ++i) space.update();
    const Vec3 p0 = space.position(handle);
    const Quat q0 = space.orientation(handle);
    for (int i = 0; i < kSettleSteps; ++i) space.update();
    EXPECT_LT((space.position(handle) - p0).norm(), 1e-4) << what << ": drifted";
    EXPECT_LT(space.orientation(handle).angularDistance(q0), 1e-3) << what << ": turned";
    EXPECT_LT(space.angular_velocity(handle).norm(), 1e-3) << what << ": spins";
    EXPECT_LT(space.linear_velocity(handle).norm(), 1e-3) << what << ": moves";
}

SpaceSettings sleepless() {
    SpaceSettings settings;
    settings.sleep.enabled = false;
    return settings;
}

TEST(CompoundResting, DumbbellOnPlaneRestsOnItsBellsAndSleeps) {
    Space space;
    add_plane(space);
    const Vec3 start(0.3, kBell + 0.2, -0.4);
    const BodyHandle bell = space.create_body(body(dumbbell(), start));
    expect_rests(space, bell, start, kBell, Quat::Identity(), "dumbbell");
}

TEST(CompoundResting, TableOnPlaneStandsOnFourLegsAndSleeps) {
    Space space;
    add_plane(space);
    const Vec3 start(1, 0.1, 2);
    const BodyHandle t = space.create_body(body(table(), start));
    expect_rests(space, t, start, 0, Quat::Identity(), "table");
}

TEST(CompoundResting, TableOnBoxStandsOnFourLegsAndSleeps) {
    Space space;
    space.create_body(body(Shape::box(Vec3(5, 0.5, 5)), Vec3(0, -0.5, 0), MotionType::Static));
    const Vec3 start(-1, 0.05, 0.5);
    const BodyHandle t = space.create_body(body(table(), start));
    expect_rests(space, t, start, 0, Quat::Identity(), "table on box");
}

TEST(CompoundResting, TableOnTriangleMeshStandsAndSleeps) {
    Space space;
    space.create_body(body(floor_mesh(), Vec3::Zero(), MotionType::Static));
    // Legs straddle cell edges: the mesh gives each its own triangle(s).
    const Vec3 start(0.5, 0.05, -0.3);
    const BodyHandle t = space.create_body(body(table(), start));
    expect_rests(space, t, start, 0, Quat::Identity(), "table on mesh");
}

TEST(CompoundResting, DumbbellOnTriangleMeshRestsOnItsBells) {
    Space space;
    space.create_body(body(floor_mesh(), Vec3::Zero(), MotionType::Static));
    const Vec3 start(0.2, kBell + 0.1, 0.7);
    const BodyHandle bell = space.create_body(body(dumbbell(), start));
    expect_rests(space, bell, start, kBell, Quat::Identity(), "dumbbell on mesh");
}

TEST(CompoundResting, DumbbellOnTableOnPlaneBothSleep) {
    Space space;
    add_plane(space);
    const Vec3 table_start(0, 0.02, 0);
    const Vec3 bell_start(0.1, kTableHeight + kBell + 0.15, 0.1);
    const BodyHandle t = space.create_body(body(table(), table_start));
    const BodyHandle bell = space.create_body(body(dumbbell(), bell_start));
    expect_rests(space, bell, bell_start, kTableHeight + kBell, Quat::Identity(), "dumbbell on table");
    expect_rests(space, t, table_start, 0, Quat::Identity(), "table under dumbbell");
}

TEST(CompoundResting, HullOnStaticTableRestsOnTheTop) {
    Space space;
    space.create_body(body(table(), Vec3::Zero(), MotionType::Static));
    const Real h = 0.2;
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i) corners.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
    const Vec3 start(0.2, kTableHeight + h + 0.1, 0.1);
    const BodyHandle cube = space.create_body(body(Shape::convex_hull(corners), start));
    expect_rests(space, cube, start, kTableHeight + h, Quat::Identity(), "hull on table");
}

TEST(CompoundResting, TurnedDumbbellRestsOnItsBarAndBells) {
    // Turned a quarter about x (the bar's axis) the dumbbell lies the same way: its bells
    // still rest on the plane.
    Space space;
    add_plane(space);
    const Vec3 start(0, kBell + 0.05, 0);
    BodyDesc d = body(dumbbell(), start);
    d.orientation = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()));
    const BodyHandle bell = space.create_body(d);
    expect_rests(space, bell, start, kBell, d.orientation, "turned dumbbell");
}

TEST(CompoundResting, TableAndDumbbellOnPlaneDoNotDrift) {
    Space space(sleepless());
    add_plane(space);
    const BodyHandle t = space.create_body(body(table(), Vec3(-2, 0, 0)));
    const BodyHandle bell = space.create_body(body(dumbbell(), Vec3(2, kBell, 0)));
    expect_no_drift(space, t, "table");
    expect_no_drift(space, bell, "dumbbell");
}

TEST(CompoundResting, TableOnMeshAndDumbbellOnTableDoNotDrift) {
    Space space(sleepless());
    space.create_body(body(floor_mesh(), Vec3::Zero(), MotionType::Static));
    const BodyHandle t = space.create_body(body(table(), Vec3(0.5, 0, -0.3)));
    const BodyHandle bell = space.create_body(body(dumbbell(), Vec3(0.5, kTableHeight + kBell, -0.3)));
    expect_no_drift(space, t, "table on mesh");
    expect_no_drift(space, bell, "dumbbell on table");
}

TEST(CompoundResting, LopsidedBenchDoesNotRock) {
    // A block near one end loads two legs far more than the other two; each leg's manifold
    // keeps its own warm start, though all four stand on the same face with the same ids.
    std::vector<CompoundPart> parts;
    parts.push_back({Shape::box(Vec3(1.1, 0.05, 0.5)), Vec3(0, 0.65, 0), Quat::Identity()});
    parts.push_back({Shape::box(Vec3(0.3, 0.3, 0.3)), Vec3(0.75, 1.0, 0), Quat::Identity()});
    for (const Real x : {-1.0, 1.0}) {
        for (const Real z : {-0.4, 0.4}) {
            parts.push_back({Shape::box(Vec3(0.05, 0.3, 0.05)), Vec3(x, 0.3, z), Quat::Identity()});
        }
    }
    Space space(sleepless());
    add_plane(space);
    const BodyHandle bench = space.create_body(body(Shape::compound(parts), Vec3::Zero()));
    expect_no_drift(space, bench, "bench");
}

TEST(CompoundContinuous, FastSpinningCompoundBarStopsAtAThinWall) {
    // Continuous's bar (a 4 m bar spinning at 60 rad/s 1 m from a 4 cm wall: its tip turns
    // through the wall within one step) made of two 2 m boxes end to end.
    auto furthest_tip = [](bool fast) {
        SpaceSettings settings = sleepless();
        settings.gravity = Vec3::Zero();
        Space space(settings);
        space.create_body(body(Shape::box(Vec3(0.02, 5, 5)), Vec3(0.5, 0, 0), MotionType::Static));
        const Vec3 half(1, 0.05, 0.05);
        const CompoundPart halves[] = {{Shape::box(half), Vec3(-1, 0, 0), Quat::Identity()},
                                       {Shape::box(half), Vec3(1, 0, 0), Quat::Identity()}};
        BodyDesc d = body(Shape::compound(halves), Vec3(-1, 0, 0));
        d.orientation = Quat(Eigen::AngleAxisd(2.0, Vec3::UnitZ()));
        d.angular_velocity = Vec3(0, 0, -60);
        d.fast = fast;
        const BodyHandle bar = space.create_body(d);
        Real tip = -kHuge;
        for (int i = 0; i < 30; ++i) {
            space.update();
            for (const Real end : {2.0, -2.0})
                tip = std::max(tip, space.position(bar).x() + (space.orientation(bar) * Vec3(end, 0, 0)).x());
        }
        return tip;
    };
    EXPECT_LT(furthest_tip(true), 0.48 + 0.01);  // the wall's near face, plus a little soft penetration
    // Unflagged, it is swept too: its tips move 1 m a step, twenty times its half-thickness.
    EXPECT_LT(furthest_tip(false), 0.48 + 0.01);
}

TEST(CompoundResting, BallChangedIntoATableStandsOnItsLegs) {
    // set_shape rebuilds the mass from the parts and remakes the contacts part by part.
    Space space;
    add_plane(space);
    const Vec3 start(0.5, 0.3, 0);
    const BodyHandle b = space.create_body(body(Shape::sphere(0.3), start));
    for (int i = 0; i < 30; ++i) space.update();
    space.set_shape(b, table());
    space.set_position(b, Vec3(start.x(), 0.02, start.z()));
    space.update();
    expect_rests(space, b, start, 0, Quat::Identity(), "ball turned table");
    const MassProperties mp = table().mass_properties(BodyDesc{}.density);
    EXPECT_NEAR(space.center_of_mass(b).y(), mp.center_of_mass.y(), kRestDepth);
}

TEST(CompoundResting, CompoundOfOneBallRollsAsTheBall) {
    auto roll = [](const Shape& shape) {
        Space space(sleepless());
        add_plane(space);
        BodyDesc d = body(shape, Vec3(0, 0.5, 0));
        d.linear_velocity = Vec3(2, 0, 0.5);
        d.angular_velocity = Vec3(1, 0, -4);
        const BodyHandle ball = space.create_body(d);
        for (int i = 0; i < 240; ++i) space.update();
        return std::pair{space.position(ball), space.orientation(ball)};
    };
    const CompoundPart one[] = {{Shape::sphere(0.5), Vec3::Zero(), Quat::Identity()}};
    const auto [ball_p, ball_q] = roll(Shape::sphere(0.5));
    const auto [compound_p, compound_q] = roll(Shape::compound(one));
    EXPECT_GT(ball_p.x(), 2);  // it rolled
    EXPECT_NEAR(ball_p.y(), 0.5, 1e-3);
    EXPECT_LT((compound_p - ball_p).norm(), 1e-9) << compound_p.transpose() << " vs " << ball_p.transpose();
    EXPECT_LT(compound_q.angularDistance(ball_q), 1e-9);
}

// A cube dropped onto the top of a table standing at `place` rests on the top, not on the floor.
void expect_cube_lands_on_table(Space& space, const Vec3& place, const char* what) {
    constexpr Real kHalf = 0.15;
    const Vec3 start = place + Vec3(0.2, kTableHeight + kHalf + 0.1, 0.1);
    const BodyHandle cube = space.create_body(body(Shape::box(Vec3::Constant(kHalf)), start));
    step_until_asleep(space, cube);
    EXPECT_NEAR(space.position(cube).y(), kTableHeight + kHalf, kRestDepth) << what;
    space.destroy_body(cube);
}

// The narrowphase takes a compound's part boxes from the broadphase only in the step it
// made them: a compound that slept, was struck and slid away, or was made static and then
// moved, is met where it is, not where its boxes were last made.
TEST(CompoundResting, TableIsMetWhereItIsAfterSleepingBeingStruckAndBeingMadeStaticAndMoved) {
    Space space;
    add_plane(space);
    const BodyHandle t = space.create_body(body(table(), Vec3(0, 0.02, 0)));
    step_until_asleep(space, t);
    ASSERT_FALSE(space.internal_is_awake(t));
    expect_cube_lands_on_table(space, space.position(t), "asleep");

    // A bar flies into the sleeping table's legs, low, and sends it sliding along x.
    step_until_asleep(space, t);
    ASSERT_FALSE(space.internal_is_awake(t));
    const Vec3 before = space.position(t);
    BodyDesc bar = body(Shape::box(Vec3(0.1, 0.1, 0.7)), before + Vec3(-2, 0.25, 0));
    bar.density = 5000;
    bar.linear_velocity = Vec3(5, 0, 0);
    bar.gravity_scale = 0;
    const BodyHandle hit = space.create_body(bar);
    for (int i = 0; i < 60; ++i) space.update();
    space.destroy_body(hit);
    step_until_asleep(space, t);
    ASSERT_FALSE(space.internal_is_awake(t));
    const Vec3 struck = space.position(t);
    ASSERT_GT(struck.x() - before.x(), 0.5) << "the ball did not move the table";
    expect_cube_lands_on_table(space, struck, "struck and moved");

    // Made static where it stands, then moved: a static body's parts have no boxes made.
    space.set_motion_type(t, MotionType::Static);
    space.update();
    const Vec3 moved = struck + Vec3(-4, 0, 3);
    space.set_position(t, moved);
    space.update();
    expect_cube_lands_on_table(space, moved, "made static and moved");
}

// Destroying compounds moves others in the broadphase's list of moving compounds: the
// ones left keep their part boxes, and a body made in a destroyed compound's slot is not
// taken for a compound.
TEST(CompoundResting, TablesLeftStandAfterOthersAreDestroyedAndTheirSlotsReused) {
    Space space;
    add_plane(space);
    std::vector<BodyHandle> tables;
    for (int i = 0; i < 4; ++i) tables.push_back(space.create_body(body(table(), Vec3(3.0 * i, 0.02, 0))));
    space.update();
    // The first goes (the last takes its place in the list), then the one that moved.
    space.destroy_body(tables[0]);
    space.update();
    space.destroy_body(tables[3]);
    space.update();
    std::vector<BodyHandle> balls;
    for (int i = 0; i < 2; ++i) balls.push_back(space.create_body(body(Shape::sphere(0.2), Vec3(3.0 * i, 0.2, 4))));
    for (const int i : {1, 2}) {
        step_until_asleep(space, tables[i]);
        EXPECT_FALSE(space.internal_is_awake(tables[i]));
        expect_cube_lands_on_table(space, space.position(tables[i]), "left standing");
    }
    // The balls in the destroyed tables' slots go, then the tables: none was left listed.
    for (const BodyHandle handle : balls) space.destroy_body(handle);
    space.update();
    for (const int i : {2, 1}) {
        space.destroy_body(tables[i]);
        space.update();
    }
    EXPECT_EQ(space.body_count(), 1u);
}

}  // namespace
}  // namespace spindle
