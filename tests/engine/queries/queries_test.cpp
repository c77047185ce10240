// Scene queries through Space (space.hpp): exact hits against every shape, the published
// step (buffered writes unseen until the update, creation and destruction seen at once,
// interpolated bodies met where their motion state puts them), filters, and bad input.
// The walk of the query tree is checked against a brute-force pass over every body.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "api/memory_report.hpp"
#include "api/space_internals.hpp"
#include "collision/cast.hpp"
#include "query/query_scene.hpp"
#include "space_calls.hpp"
#include "world.hpp"

namespace spindle {
namespace {

SpaceSettings weightless() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    return s;
}

BodyDesc body(const Shape& shape, const Vec3& position, MotionType type = MotionType::Dynamic) {
    BodyDesc d;
    d.type = type;
    d.shape = shape;
    d.position = position;
    return d;
}

using test::error_of;

TEST(SceneQueries, RayHitsTheNearestBodyOnItsSurface) {
    Space space(weightless());
    const BodyHandle near = space.create_body(body(Shape::sphere(0.5), {0, 0, 0}));
    const BodyHandle far = space.create_body(body(Shape::sphere(0.5), {2, 0, 0}));
    const std::optional<QueryHit> hit = space.cast_ray({-5, 0, 0}, {5, 0, 0});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->body, near);
    EXPECT_NEAR(hit->fraction, 0.45, 1e-12);
    EXPECT_NEAR((hit->point - Vec3(-0.5, 0, 0)).norm(), 0, 1e-12);
    EXPECT_NEAR((hit->normal - Vec3(-1, 0, 0)).norm(), 0, 1e-12);

    std::vector<QueryHit> hits;
    ASSERT_EQ(space.cast_ray_all({5, 0, 0}, {-5, 0, 0}, hits), 2u);  // from the other side: far first
    EXPECT_EQ(hits[0].body, far);
    EXPECT_NEAR(hits[0].fraction, 0.25, 1e-12);
    EXPECT_EQ(hits[1].body, near);
    EXPECT_NEAR(hits[1].fraction, 0.45, 1e-12);
    EXPECT_TRUE(space.ray_hits_any({0, -5, 0}, {0, 5, 0}));
    EXPECT_FALSE(space.ray_hits_any({0, -5, 3}, {0, 5, 3}));
}

// A box's bounds are met, but not the sphere inside it.
TEST(SceneQueries, RayMissesTheBoundsOfARoundShape) {
    Space space(weightless());
    space.create_body(body(Shape::sphere(0.5), {0, 0, 0}));
    EXPECT_FALSE(space.cast_ray({-5, 0.45, 0.45}, {5, 0.45, 0.45}));
    EXPECT_TRUE(space.cast_ray({-5, 0.3, 0.3}, {5, 0.3, 0.3}));
}

TEST(SceneQueries, RaysSweepsAndOverlapsMeetEveryKindOfShape) {
    Space space(weightless());
    const std::vector<Vec3> corners = {{-0.5, -0.5, -0.5}, {0.5, -0.5, -0.5}, {0, 0.5, -0.5}, {0, 0, 0.5}};
    const std::vector<Vec3> tri = {{-1, 0, -1}, {1, 0, -1}, {0, 0, 1}};
    const std::vector<std::uint32_t> one = {0, 1, 2};
    const BodyHandle ground = space.create_body(body(Shape::plane({0, 1, 0}, -10), {0, 0, 0}, MotionType::Static));
    const BodyHandle mesh = space.create_body(body(Shape::triangle_mesh(tri, one), {20, -2, 0}, MotionType::Static));
    struct Case {
        BodyHandle handle;
        Real x, top;  // a vertical ray at x, z = 0 first meets the body at y = top
    };
    const std::vector<Case> cases = {
        {space.create_body(body(Shape::sphere(0.5), {0, 0, 0})), 0, 0.5},
        {space.create_body(body(Shape::box({1, 0.25, 1}), {4, 0, 0})), 4, 0.25},
        {space.create_body(body(Shape::capsule(0.5, 0.25), {8, 0, 0})), 8, 0.75},
        {space.create_body(body(Shape::convex_hull(corners), {12, 0, 0})), 12, 0.25},  // the slanted face at z=0
        {mesh, 20, -2},
        {ground, 30, -10},
    };
    for (const Case& c : cases) {
        const std::optional<QueryHit> hit = space.cast_ray({c.x, 20, 0}, {c.x, -20, 0});
        ASSERT_TRUE(hit) << "x " << c.x;
        EXPECT_EQ(hit->body, c.handle) << "x " << c.x;
        EXPECT_NEAR(hit->point.y(), c.top, 1e-9) << "x " << c.x;
        // A small sphere dropped down the same line, and one resting just inside the top.
        // (The hull's top face is slanted: the sphere meets it off the line, lower down.)
        const Shape probe = Shape::sphere(0.05);
        const std::optional<QueryHit> swept = space.cast_shape(probe, {{c.x, 20, 0}, Quat::Identity()}, {0, -40, 0});
        ASSERT_TRUE(swept) << "x " << c.x;
        EXPECT_EQ(swept->body, c.handle) << "x " << c.x;
        if (c.x != 12) {
            EXPECT_NEAR(swept->point.y(), c.top, 1e-4) << "x " << c.x;
            EXPECT_NEAR(swept->fraction, (20 - 0.05 - c.top) / 40, 1e-5) << "x " << c.x;
        }
        std::vector<BodyHandle> touching;
        EXPECT_EQ(space.overlap_shape(probe, {{c.x, c.top - 0.01, 0}, Quat::Identity()}, touching), 1u) << "x " << c.x;
        EXPECT_EQ(space.overlap_shape(probe, {{c.x, c.top + 0.5, 0}, Quat::Identity()}, touching), 0u) << "x " << c.x;
    }
}

TEST(SceneQueries, BufferedWritesAreMetAfterTheUpdateCreationAndDestructionAtOnce) {
    Space space(weightless());
    const BodyHandle a = space.create_body(body(Shape::sphere(0.5), {0, 0, 0}));
    space.set_position(a, {3, 0, 0});
    // Not yet applied: the ray meets the body where reads put it.
    ASSERT_TRUE(space.cast_ray({0, 5, 0}, {0, -5, 0}));
    EXPECT_FALSE(space.cast_ray({3, 5, 0}, {3, -5, 0}));
    space.update();
    EXPECT_FALSE(space.cast_ray({0, 5, 0}, {0, -5, 0}));
    ASSERT_TRUE(space.cast_ray({3, 5, 0}, {3, -5, 0}));
    EXPECT_EQ(space.position(a), Vec3(3, 0, 0));

    const BodyHandle b = space.create_body(body(Shape::box({0.5, 0.5, 0.5}), {-3, 0, 0}));
    const std::optional<QueryHit> made = space.cast_ray({-3, 5, 0}, {-3, -5, 0});
    ASSERT_TRUE(made);
    EXPECT_EQ(made->body, b);
    space.destroy_body(b);
    EXPECT_FALSE(space.cast_ray({-3, 5, 0}, {-3, -5, 0}));
    space.update();
    space.update();  // both published scenes have it gone
    EXPECT_FALSE(space.cast_ray({-3, 5, 0}, {-3, -5, 0}));
}

// With internal time stepping a moving body is read between its last two steps; a ray
// meets it exactly there, not at the newest step.
TEST(SceneQueries, RayMeetsAnInterpolatedBodyWhereItsMotionStateIs) {
    SpaceSettings settings = weightless();
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    BodyDesc d = body(Shape::sphere(0.5), {0, 0, 0});
    d.linear_velocity = {6, 0, 0};
    d.angular_velocity = {0, 0, 3};
    const BodyHandle a = space.create_body(d);
    const Real dt = settings.time_step.duration;
    space.update(2.5 * dt);  // two steps and half a step banked: alpha 0.5
    ASSERT_NEAR(space.motion_states().alpha(), 0.5, 1e-9);
    const MotionState seen = space.motion_state(a);
    const MotionState raw = space.internal_motion_state(a);
    ASSERT_GT((raw.position - seen.position).norm(), 0.04);  // a tenth of a step's travel apart: it matters
    const std::optional<QueryHit> hit = space.cast_ray({-5, 0, 0}, {5, 0, 0});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->point.x(), seen.position.x() - 0.5, 1e-12);
}

// A rod turning 170 degrees a step, read half way: lying almost upright, far outside the
// boxes of its two nearly flat end poses. The query tree must still hold it there.
TEST(SceneQueries, RayMeetsABodyTurnedFarBetweenItsSteps) {
    SpaceSettings settings = weightless();
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    BodyDesc d = body(Shape::box({2, 0.05, 0.05}), {0, 0, 0});
    const Real dt = settings.time_step.duration;
    d.angular_velocity = {0, 0, 170 * kPi / 180 / dt};
    const BodyHandle rod = space.create_body(d);
    space.update(1.5 * dt);
    ASSERT_NEAR(space.motion_states().alpha(), 0.5, 1e-9);
    const MotionState seen = space.motion_state(rod);
    const Vec3 axis = seen.orientation * Vec3::UnitX();
    ASSERT_GT(std::abs(axis.y()), 0.95);  // near upright as read (0.989 when written)
    CastHit expected;
    ASSERT_TRUE(
        ray_cast(Shape::box({2, 0.05, 0.05}), {seen.position, seen.orientation}, {0.1, 5, 0}, {0.1, -5, 0}, expected));
    const std::optional<QueryHit> hit = space.cast_ray({0.1, 5, 0}, {0.1, -5, 0});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->body, rod);
    EXPECT_EQ(hit->fraction, expected.fraction);
}

TEST(SceneQueries, FiltersSkipLayersGroupsTheIgnoredBodyAndRejectedBodies) {
    Space space(weightless());
    BodyDesc d = body(Shape::sphere(0.5), {0, 0, 0});
    d.layer = 3;
    d.group = 7;
    const BodyHandle first = space.create_body(d);
    const BodyHandle second = space.create_body(body(Shape::sphere(0.5), {2, 0, 0}));  // layer 0, no group
    auto nearest = [&](const QueryFilter& filter) {
        const std::optional<QueryHit> hit = space.cast_ray({-5, 0, 0}, {5, 0, 0}, filter);
        return hit ? hit->body : BodyHandle{};
    };
    auto with = [](auto set) {
        QueryFilter filter;
        set(filter);
        return filter;
    };
    EXPECT_EQ(nearest({}), first);
    EXPECT_EQ(nearest(with([](QueryFilter& f) { f.layer_mask = ~(1u << 3); })), second);
    EXPECT_EQ(nearest(with([](QueryFilter& f) { f.layer_mask = 1u << 3; })), first);
    EXPECT_EQ(nearest(with([](QueryFilter& f) { f.layer_mask = 1u << 5; })), BodyHandle{});
    EXPECT_EQ(nearest(with([](QueryFilter& f) { f.group = 7; })), second);
    EXPECT_EQ(nearest(with([](QueryFilter& f) { f.group = 8; })), first);
    EXPECT_EQ(nearest(with([&](QueryFilter& f) { f.ignore = first; })), second);
    EXPECT_EQ(nearest(with([&](QueryFilter& f) { f.accept = [&](BodyHandle h) { return h != first; }; })), second);
    std::vector<BodyHandle> touching;
    EXPECT_EQ(space.overlap_box({{-10, -10, -10}, {10, 10, 10}}, touching,
                                with([&](QueryFilter& f) { f.ignore = second; })),
              1u);
    EXPECT_EQ(touching[0], first);
}

// A trigger volume is passed through unless the filter asks for sensors.
TEST(SceneQueries, SensorsAreMetOnlyWhenTheFilterAsks) {
    Space space(weightless());
    BodyDesc trigger = body(Shape::box({1, 1, 1}), {0, 0, 0}, MotionType::Static);
    trigger.sensor = true;
    const BodyHandle sensor = space.create_body(trigger);
    const BodyHandle wall = space.create_body(body(Shape::box({0.5, 2, 2}), {4, 0, 0}, MotionType::Static));
    const std::optional<QueryHit> through = space.cast_ray({-5, 0, 0}, {5, 0, 0});
    ASSERT_TRUE(through);
    EXPECT_EQ(through->body, wall);
    QueryFilter with_sensors;
    with_sensors.sensors = true;
    const std::optional<QueryHit> stopped = space.cast_ray({-5, 0, 0}, {5, 0, 0}, with_sensors);
    ASSERT_TRUE(stopped);
    EXPECT_EQ(stopped->body, sensor);
    std::vector<BodyHandle> inside;
    EXPECT_EQ(space.overlap_box({{-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}}, inside), 0u);
    EXPECT_EQ(space.overlap_box({{-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}}, inside, with_sensors), 1u);
}

TEST(SceneQueries, ShapeCastFindsTheFirstTimeOfImpact) {
    Space space(weightless());
    const BodyHandle target = space.create_body(body(Shape::box({1, 1, 1}), {0, 0, 0}));
    const std::optional<QueryHit> hit = space.cast_shape(Shape::sphere(0.5), {{-5, 0, 0}, Quat::Identity()},
                                                         {10, 0, 0});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->body, target);
    EXPECT_NEAR(hit->fraction, 0.35, 1e-5);
    EXPECT_NEAR(hit->point.x(), -1, 1e-5);
    EXPECT_NEAR((hit->normal - Vec3(-1, 0, 0)).norm(), 0, 1e-6);
    // Past it, aside of it, and overlapping from the start.
    EXPECT_FALSE(space.cast_shape(Shape::sphere(0.5), {{-5, 2, 0}, Quat::Identity()}, {10, 0, 0}));
    EXPECT_FALSE(space.cast_shape(Shape::capsule(0.5, 0.25), {{5, 0, 0}, Quat::Identity()}, {10, 0, 0}));
    const std::optional<QueryHit> inside = space.cast_shape(Shape::box({0.2, 0.2, 0.2}), {}, {1, 0, 0});
    ASSERT_TRUE(inside);
    EXPECT_EQ(inside->fraction, 0);
}

TEST(SceneQueries, OverlapsAreExactAgainstTheShapes) {
    Space space(weightless());
    const BodyHandle ball = space.create_body(body(Shape::sphere(0.5), {0, 0, 0}));
    const BodyHandle crate = space.create_body(body(Shape::box({0.5, 0.5, 0.5}), {3, 0, 0}));
    std::vector<BodyHandle> found;
    // A box in the sphere's bounding-box corner: the bounds meet, the sphere does not.
    EXPECT_EQ(space.overlap_box({{0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}}, found), 0u);
    EXPECT_EQ(space.overlap_box({{2.4, 0.4, 0.4}, {2.6, 0.6, 0.6}}, found), 1u);
    EXPECT_EQ(found[0], crate);
    EXPECT_EQ(space.overlap_shape(Shape::sphere(0.2), {{0.5, 0.5, 0}, Quat::Identity()}, found), 0u);
    EXPECT_EQ(space.overlap_shape(Shape::sphere(0.2), {{0.4, 0.4, 0}, Quat::Identity()}, found), 1u);
    EXPECT_EQ(found[0], ball);
    EXPECT_EQ(space.overlap_shape(Shape::capsule(2, 0.1),
                                  {{1.5, 0, 0}, Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()))}, found),
              2u);
    EXPECT_EQ(found[0], ball);
    EXPECT_EQ(found[1], crate);
}

TEST(SceneQueries, BadArgumentsAreNamed) {
    Space space(weightless());
    space.create_body(body(Shape::sphere(0.5), {0, 0, 0}));
    const Real nan = std::nan("");
    std::vector<QueryHit> hits;
    std::vector<BodyHandle> bodies;
    EXPECT_NE(error_of([&] { space.cast_ray({nan, 0, 0}, {1, 0, 0}); }).find("cast_ray: from"), std::string::npos);
    EXPECT_NE(error_of([&] {
                  space.cast_ray_all({0, 0, 0}, {1, INFINITY, 0}, hits);
              }).find("cast_ray_all: to"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  space.cast_shape(Shape::plane({0, 1, 0}, 0), {}, {1, 0, 0});
              }).find("shape must be a sphere, capsule, box or convex hull, got plane"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  space.cast_shape(Shape::sphere(1), {}, {nan, 0, 0});
              }).find("translation"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  space.overlap_shape(Shape::sphere(1), {{0, 0, 0}, Quat(0, 0, 0, 0)}, bodies);
              }).find("pose.q"),
              std::string::npos);
    EXPECT_NE(error_of([&] { space.overlap_box({{1, 0, 0}, {0, 1, 1}}, bodies); }).find("box.min"), std::string::npos);
}

// What compare_with_brute_force saw: rays that met a body other than the first (the
// ground in the piles below), and bodies the overlaps found.
struct Compared {
    int rays = 0, hits = 0, overlapped = 0;
};

// Rays from above and an overlap through the published step, each answered by the space
// and by a brute-force pass over every body at the pose reads give it, exactly the same.
Compared compare_with_brute_force(const Space& space, std::mt19937& random, int rays) {
    std::uniform_real_distribution<Real> spread(-4, 4);
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    space.motion_states().get_all_motion_states(handles, states);
    std::vector<Shape> shapes;
    for (BodyHandle h : handles) shapes.push_back(space.internal_desc(h).shape);
    Compared seen;
    for (int r = 0; r < rays; ++r) {
        const Vec3 from(spread(random), 20 + spread(random), spread(random));
        const Vec3 to(spread(random), -1, spread(random));
        Real best = 2;
        BodyHandle nearest{};
        for (std::size_t k = 0; k < handles.size(); ++k) {
            CastHit h;
            if (ray_cast(shapes[k], {states[k].position, states[k].orientation}, from, to, h) && h.fraction < best) {
                best = h.fraction;
                nearest = handles[k];
            }
        }
        const std::optional<QueryHit> hit = space.cast_ray(from, to);
        EXPECT_EQ(hit.has_value(), best <= 1)
            << "nearest " << to_string(nearest) << " from " << from.transpose() << " to " << to.transpose();
        if (hit) {
            EXPECT_EQ(hit->body, nearest);
            EXPECT_EQ(hit->fraction, best);
            seen.hits += hit->body != handles[0];
        }
        ++seen.rays;
    }
    const Transform probe{{spread(random), 0.5 + std::abs(spread(random)), spread(random)}, Quat::Identity()};
    std::vector<BodyHandle> expected, found;
    for (std::size_t k = 0; k < handles.size(); ++k) {
        if (overlaps(Shape::sphere(1), probe, shapes[k], {states[k].position, states[k].orientation})) {
            expected.push_back(handles[k]);
        }
    }
    space.overlap_shape(Shape::sphere(1), probe, found);
    EXPECT_EQ(found, expected);
    seen.overlapped += static_cast<int>(found.size());
    return seen;
}

// A falling, tumbling pile of mixed shapes, stepped with internal time stepping so that
// reads blend between steps.
void make_tumbling_pile(Space& space, std::mt19937& random) {
    space.create_body(body(Shape::plane({0, 1, 0}, 0), {0, 0, 0}, MotionType::Static));
    std::uniform_real_distribution<Real> spread(-4, 4), spin(-6, 6);
    const Shape shapes[] = {Shape::sphere(0.3), Shape::box({0.4, 0.2, 0.3}), Shape::capsule(0.3, 0.15)};
    for (int i = 0; i < 120; ++i) {
        BodyDesc d = body(shapes[i % 3], {spread(random), 1 + 0.3 * i, spread(random)});
        d.angular_velocity = {spin(random), spin(random), spin(random)};
        d.linear_velocity = {spin(random), 0, spin(random)};
        space.create_body(d);
    }
}

SpaceSettings blending() {
    SpaceSettings settings;
    settings.time_step.use_internal_time_stepping = true;
    return settings;
}

// The pile read between steps: every query the tree answers equals a brute-force pass
// over every body at its published pose.
TEST(SceneQueries, TreeAnswersAsABruteForcePassOverEveryBody) {
    Space space(blending());
    std::mt19937 random(7);
    make_tumbling_pile(space, random);
    Compared seen;
    for (int frame = 0; frame < 60; ++frame) {
        space.update(1.0 / 47);  // a frame rate that leaves a different alpha each time
        const Compared now = compare_with_brute_force(space, random, 20);
        seen.rays += now.rays;
        seen.hits += now.hits;
        seen.overlapped += now.overlapped;
        for (const auto& scene : SpaceInternals::world(space).query_scenes) {
            if (scene) scene->tree().validate();  // one of them may wait for the next flip (query_lease.cpp)
        }
    }
    EXPECT_EQ(seen.rays, 1200);
    EXPECT_GT(seen.overlapped, 20);  // 36 when written: the probes meet bodies, not only nothing
    EXPECT_GT(seen.hits, 100);       // the rays meet the moving bodies, not only the ground
}

// Until its first query a space keeps no query scene and its flips do no query work; the
// physics is the same either way (the state hash of a space queried every frame).
TEST(SceneQueries, ASpaceThatNeverQueriesKeepsNoQueryScene) {
    Space quiet(blending()), queried(blending());
    std::mt19937 random_quiet(7), random_queried(7);
    make_tumbling_pile(quiet, random_quiet);
    make_tumbling_pile(queried, random_queried);
    for (int frame = 0; frame < 40; ++frame) {
        quiet.update(1.0 / 47);
        queried.update(1.0 / 47);
        queried.ray_hits_any({0, 20, 0}, {0, -1, 0});
    }
    const World& world = SpaceInternals::world(quiet);
    EXPECT_EQ(world.query_scenes[0], nullptr);
    EXPECT_EQ(world.query_scenes[1], nullptr);
    EXPECT_EQ(memory_report(quiet).query_scenes, 0u);
    EXPECT_GT(memory_report(queried).query_scenes, 0u);
    EXPECT_EQ(quiet.state_hash(), queried.state_hash());
}

// The first query of a space that stepped without any: the scenes are built from what
// reads return, not from the live state (a direct change is not published before the
// update), and from then on the flips keep them.
TEST(SceneQueries, FirstQueryAfterStepsMeetsBodiesAsABruteForcePass) {
    Space space(blending());
    std::mt19937 random(11);
    make_tumbling_pile(space, random);
    for (int frame = 0; frame < 30; ++frame) space.update(1.0 / 47);
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    space.motion_states().get_all_motion_states(handles, states);
    MotionState moved = space.internal_motion_state(handles[5]);
    moved.position += Vec3(0, 50, 0);
    space.set_internal_motion_state(handles[5], moved);  // live now, published at the next flip
    ASSERT_EQ(SpaceInternals::world(space).query_scenes[0], nullptr);
    const Compared first = compare_with_brute_force(space, random, 40);
    EXPECT_GT(first.hits, 5);
    // Where the read puts the moved body (its centre is inside it), not where it lives now.
    std::vector<BodyHandle> at_read;
    space.overlap_shape(Shape::sphere(0.01), {space.motion_state(handles[5]).position, Quat::Identity()}, at_read);
    EXPECT_NE(std::find(at_read.begin(), at_read.end(), handles[5]), at_read.end());
    EXPECT_FALSE(space.ray_hits_any(moved.position + Vec3(0, 0, 5), moved.position + Vec3(0, 0, -5)));
    for (int frame = 0; frame < 20; ++frame) {
        space.update(1.0 / 47);
        compare_with_brute_force(space, random, 10);
        for (const auto& scene : SpaceInternals::world(space).query_scenes) {
            if (scene) scene->tree().validate();  // one of them may wait for the next flip (query_lease.cpp)
        }
    }
}

}  // namespace
}  // namespace spindle
