// Scene queries through Space (space.hpp): exact hits against every shape, the published
// step (buffered writes unseen until the update, creation and destruction seen at once,
// interpolated bodies met where their motion state puts them), filters, and bad input.
// The walk of the query tree is checked against a brute-force pass over every body.
#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "api/space_internals.hpp"
#include "collision/cast.hpp"
#include "query/query_scene.hpp"
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

std::string message_of(const std::function<void()>& call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

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
    EXPECT_NE(message_of([&] { space.cast_ray({nan, 0, 0}, {1, 0, 0}); }).find("cast_ray: from"), std::string::npos);
    EXPECT_NE(message_of([&] {
                  space.cast_ray_all({0, 0, 0}, {1, INFINITY, 0}, hits);
              }).find("cast_ray_all: to"),
              std::string::npos);
    EXPECT_NE(message_of([&] {
                  space.cast_shape(Shape::plane({0, 1, 0}, 0), {}, {1, 0, 0});
              }).find("shape must be a sphere, capsule, box or convex hull, got plane"),
              std::string::npos);
    EXPECT_NE(message_of([&] {
                  space.cast_shape(Shape::sphere(1), {}, {nan, 0, 0});
              }).find("translation"),
              std::string::npos);
    EXPECT_NE(message_of([&] {
                  space.overlap_shape(Shape::sphere(1), {{0, 0, 0}, Quat(0, 0, 0, 0)}, bodies);
              }).find("pose.q"),
              std::string::npos);
    EXPECT_NE(message_of([&] {
                  space.overlap_box({{1, 0, 0}, {0, 1, 1}}, bodies);
              }).find("box.min"),
              std::string::npos);
}

// A falling, tumbling pile of mixed shapes read between steps: every query the tree
// answers equals a brute-force pass over every body at its published pose.
TEST(SceneQueries, TreeAnswersAsABruteForcePassOverEveryBody) {
    SpaceSettings settings;
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    space.create_body(body(Shape::plane({0, 1, 0}, 0), {0, 0, 0}, MotionType::Static));
    std::mt19937 random(7);
    std::uniform_real_distribution<Real> spread(-4, 4), spin(-6, 6);
    const Shape shapes[] = {Shape::sphere(0.3), Shape::box({0.4, 0.2, 0.3}), Shape::capsule(0.3, 0.15)};
    for (int i = 0; i < 120; ++i) {
        BodyDesc d = body(shapes[i % 3], {spread(random), 1 + 0.3 * i, spread(random)});
        d.angular_velocity = {spin(random), spin(random), spin(random)};
        d.linear_velocity = {spin(random), 0, spin(random)};
        space.create_body(d);
    }
    std::vector<BodyHandle> handles;
    std::vector<MotionState> states;
    int checked = 0, hits_seen = 0, overlaps_seen = 0;
    for (int frame = 0; frame < 60; ++frame) {
        space.update(1.0 / 47);  // a frame rate that leaves a different alpha each time
        space.motion_states().get_all_motion_states(handles, states);
        for (int r = 0; r < 20; ++r) {
            const Vec3 from(spread(random), 20 + spread(random), spread(random));
            const Vec3 to(spread(random), -1, spread(random));
            // Brute force: every body at its read pose.
            Real best = 2;
            BodyHandle nearest{};
            for (std::size_t k = 0; k < handles.size(); ++k) {
                CastHit h;
                const Shape shape = space.internal_desc(handles[k]).shape;
                if (ray_cast(shape, {states[k].position, states[k].orientation}, from, to, h) && h.fraction < best) {
                    best = h.fraction;
                    nearest = handles[k];
                }
            }
            const std::optional<QueryHit> hit = space.cast_ray(from, to);
            ASSERT_EQ(hit.has_value(), best <= 1) << "frame " << frame << " nearest " << to_string(nearest) << " from "
                                                  << from.transpose() << " to " << to.transpose();
            if (hit) {
                EXPECT_EQ(hit->body, nearest) << "frame " << frame;
                EXPECT_EQ(hit->fraction, best) << "frame " << frame;
                hits_seen += hit->body != handles[0];
            }
            ++checked;
        }
        // Overlaps, the same way.
        const Transform probe{{spread(random), 0.5 + std::abs(spread(random)), spread(random)}, Quat::Identity()};
        std::vector<BodyHandle> expected, found;
        for (std::size_t k = 0; k < handles.size(); ++k) {
            const Shape shape = space.internal_desc(handles[k]).shape;
            if (overlaps(Shape::sphere(1), probe, shape, {states[k].position, states[k].orientation})) {
                expected.push_back(handles[k]);
            }
        }
        space.overlap_shape(Shape::sphere(1), probe, found);
        EXPECT_EQ(found, expected) << "frame " << frame;
        overlaps_seen += static_cast<int>(found.size());
        for (const auto& scene : SpaceInternals::world(space).query_scenes) scene->tree().validate();
    }
    EXPECT_EQ(checked, 1200);
    EXPECT_GT(overlaps_seen, 20);  // 36 when written: the probes meet bodies, not only nothing
    EXPECT_GT(hits_seen, 100);     // the rays meet the moving bodies, not only the ground
}

}  // namespace
}  // namespace spindle
