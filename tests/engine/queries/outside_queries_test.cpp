// Scene queries at their edges, as an outside tester tried them: rays of no length,
// rays starting inside or on a body, rays along faces and edges and through the shared
// edges and vertices of a mesh, rays a billion metres long, sweeps that do not move,
// filters that throw or query again. Every ray function agrees with the others.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "grid_mesh.hpp"
#include "space_calls.hpp"

namespace spindle::outside_queries_test {
namespace {

SpaceSettings still() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    s.sleep.enabled = false;
    return s;
}

BodyDesc body(const Shape& shape, const Vec3& position, MotionType type = MotionType::Static) {
    BodyDesc d;
    d.type = type;
    d.shape = shape;
    d.position = position;
    return d;
}

// cast_ray, ray_hits_any and cast_ray_all say the same about a segment: the nearest of
// cast_ray_all is cast_ray's hit, and any hit has a point on the segment, a unit normal
// and a fraction in [0, 1].
std::optional<QueryHit> agreed_ray(const Space& space, const Vec3& from, const Vec3& to,
                                   const QueryFilter& filter = {}) {
    const std::optional<QueryHit> hit = space.cast_ray(from, to, filter);
    const bool any = space.ray_hits_any(from, to, filter);
    std::vector<QueryHit> all;
    space.cast_ray_all(from, to, all, filter);
    const std::string what = "ray " + std::to_string(from.x()) + "," + std::to_string(from.y()) + "," +
                             std::to_string(from.z()) + " -> " + std::to_string(to.x()) + "," + std::to_string(to.y()) +
                             "," + std::to_string(to.z());
    EXPECT_EQ(hit.has_value(), any) << what;
    EXPECT_EQ(hit.has_value(), !all.empty()) << what;
    if (hit && !all.empty()) {
        EXPECT_EQ(all.front().body, hit->body) << what;
        EXPECT_EQ(all.front().fraction, hit->fraction) << what;
    }
    for (const QueryHit& h : all) {
        EXPECT_TRUE(h.fraction >= 0 && h.fraction <= 1) << what << " fraction " << h.fraction;
        EXPECT_NEAR(h.normal.norm(), 1, 1e-9) << what;
        // On the segment where the fraction says (a metre-scale tolerance of 1e-9 relative).
        const Vec3 on = from + h.fraction * (to - from);
        EXPECT_LE((on - h.point).norm(), 1e-9 * (1 + (to - from).norm())) << what;
    }
    return hit;
}

}  // namespace

TEST(OutsideQueries, ZeroLengthRaysMeetNothingAnywhere) {
    Space space(still());
    space.create_body(body(Shape::sphere(1), Vec3::Zero()));
    space.create_body(body(Shape::box(Vec3(1, 1, 1)), Vec3(5, 0, 0)));
    space.create_body(body(test::flat_grid_mesh(4, 1), Vec3(0, -3, 0)));
    space.create_body(body(Shape::plane(Vec3::UnitY(), -10), Vec3::Zero()));
    for (const Vec3& p :
         {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(6, 1, 1), Vec3(0, -3, 0), Vec3(0, -10, 0), Vec3(9, 9, 9)}) {
        EXPECT_FALSE(agreed_ray(space, p, p).has_value()) << p.transpose();
    }
}

// A ray starting inside a solid does not hit it (query.hpp), but does hit what lies
// beyond it, for every convex kind and a compound's part.
TEST(OutsideQueries, RayStartingInsideABodyMeetsTheBodyBeyondIt) {
    const CompoundPart parts[] = {{Shape::box(Vec3(1, 1, 1)), Vec3::Zero(), Quat::Identity()},
                                  {Shape::sphere(0.5), Vec3(0, 2, 0), Quat::Identity()}};
    const std::vector<Shape> shapes{
        Shape::sphere(1), Shape::box(Vec3(1, 1, 1)), Shape::capsule(0.5, 1),
        Shape::convex_hull(std::vector<Vec3>{
            {-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1}}),
        Shape::compound(parts)};
    for (const Shape& shape : shapes) {
        SCOPED_TRACE(to_string(shape.type));
        Space space(still());
        const BodyHandle inside = space.create_body(body(shape, Vec3::Zero()));
        const BodyHandle beyond = space.create_body(body(Shape::box(Vec3(0.5, 0.5, 0.5)), Vec3(4, 0, 0)));
        const std::optional<QueryHit> hit = agreed_ray(space, Vec3(0.1, 0.05, 0), Vec3(10, 0.05, 0));
        ASSERT_TRUE(hit.has_value());
        EXPECT_EQ(hit->body, beyond);
        EXPECT_NEAR(hit->point.x(), 3.5, 1e-9);
        // The other way it meets nothing but the body it starts in.
        EXPECT_FALSE(agreed_ray(space, Vec3(0.1, 0.05, 0), Vec3(-10, 0.05, 0)).has_value());
        // From outside it meets the first body.
        const std::optional<QueryHit> in = agreed_ray(space, Vec3(-10, 0.05, 0), Vec3(10, 0.05, 0));
        ASSERT_TRUE(in.has_value());
        EXPECT_EQ(in->body, inside);
    }
}

// Rays along a box's faces, edges and through its corners: the ray functions agree and
// any hit is on the box's surface.
TEST(OutsideQueries, RaysAlongFacesEdgesAndCornersAgreeAndHitTheSurface) {
    Space space(still());
    space.create_body(body(Shape::box(Vec3(1, 1, 1)), Vec3::Zero()));
    const std::vector<std::pair<Vec3, Vec3>> rays{
        {{-5, 1, 0}, {5, 1, 0}},                  // along the top face
        {{-5, 1, 1}, {5, 1, 1}},                  // along the top front edge
        {{-5, -5, -5}, {5, 5, 5}},                // through two corners
        {{0, 5, 0}, {0, 1, 0}},                   // ending on the top face
        {{0, 1, 0}, {0, 5, 0}},                   // starting on the top face, leaving
        {{0, 1, 0}, {0, -5, 0}},                  // starting on the top face, entering
        {{1, 5, 1}, {1, -5, 1}},                  // down a vertical edge
        {{-5, 1 + 1e-12, 0}, {5, 1 + 1e-12, 0}},  // just above the top face
        {{-5, 1 - 1e-12, 0}, {5, 1 - 1e-12, 0}},  // just inside it
    };
    for (const auto& [from, to] : rays) {
        const std::optional<QueryHit> hit = agreed_ray(space, from, to);
        if (hit) {
            EXPECT_LE(hit->point.cwiseAbs().maxCoeff(), 1 + 1e-9) << hit->point.transpose();
        }
    }
    // Straight down onto the top face's middle and onto the corner: both hit at y = 1.
    for (const Vec3& x : {Vec3(0, 0, 0), Vec3(1, 0, 1), Vec3(1, 0, 0)}) {
        const std::optional<QueryHit> hit = agreed_ray(space, x + Vec3(0, 5, 0), x + Vec3(0, -5, 0));
        ASSERT_TRUE(hit.has_value()) << x.transpose();
        EXPECT_NEAR(hit->point.y(), 1, 1e-12);
    }
}

// A mesh has no cracks: a ray down through any of its vertices, through the midpoint of
// any shared edge, or along the diagonal every cell splits on, hits it, at the surface.
TEST(OutsideQueries, RaysThroughAMeshsSharedEdgesAndVerticesHitIt) {
    Space space(still());
    const BodyHandle mesh = space.create_body(body(test::flat_grid_mesh(4, 1), Vec3(0, 0, 0)));
    int rays = 0;
    for (Real x = -2; x <= 2; x += 0.5) {
        for (Real z = -2; z <= 2; z += 0.5) {
            // Inside the grid's outline (its outer border may be met or not).
            if (std::abs(x) >= 2 || std::abs(z) >= 2) continue;
            const std::optional<QueryHit> hit = agreed_ray(space, Vec3(x, 3, z), Vec3(x, -3, z));
            ASSERT_TRUE(hit.has_value()) << x << ", " << z;
            EXPECT_EQ(hit->body, mesh);
            EXPECT_NEAR(hit->point.y(), 0, 1e-12);
            EXPECT_NEAR(hit->normal.y(), 1, 1e-12);
            // A slanted ray through the same point.
            const std::optional<QueryHit> slant = agreed_ray(space, Vec3(x - 1, 2, z + 0.5), Vec3(x + 1, -2, z - 0.5));
            ASSERT_TRUE(slant.has_value()) << x << ", " << z;
            EXPECT_NEAR(slant->point.x(), x, 1e-9);
            ++rays;
        }
    }
    EXPECT_EQ(rays, 49);
    // From below, against the mesh's back: one-sided or not, the three functions agree.
    agreed_ray(space, Vec3(0.5, -3, 0.5), Vec3(0.5, 3, 0.5));
    agreed_ray(space, Vec3(0, -3, 0), Vec3(0, 3, 0));
}

// Rays a billion metres long (the positions' bound) meet small bodies where short rays do.
TEST(OutsideQueries, RaysABillionMetresLongHitSmallBodiesOnTheirSurface) {
    const std::vector<Shape> shapes{Shape::sphere(0.5), Shape::box(Vec3(0.5, 0.5, 0.5)), Shape::capsule(0.25, 0.25),
                                    Shape::convex_hull(std::vector<Vec3>{{-0.5, -0.5, -0.5},
                                                                         {0.5, -0.5, -0.5},
                                                                         {-0.5, 0.5, -0.5},
                                                                         {0.5, 0.5, -0.5},
                                                                         {-0.5, -0.5, 0.5},
                                                                         {0.5, -0.5, 0.5},
                                                                         {-0.5, 0.5, 0.5},
                                                                         {0.5, 0.5, 0.5}}),
                                    test::flat_grid_mesh(2, 0.5)};
    const Real far = 1e9;
    for (const Shape& shape : shapes) {
        SCOPED_TRACE(to_string(shape.type));
        Space space(still());
        const BodyHandle b = space.create_body(body(shape, Vec3::Zero()));
        // From a billion metres away, down and slanted: where a ten-metre ray on the same
        // line meets the body.
        const Real top = shape.type == ShapeType::TriangleMesh ? 0 : 0.5;
        const Vec3 target(0.01, 0, 0.02);
        for (const Vec3& direction : {Vec3(0, -1, 0), Vec3(0, -1, 0.5), Vec3(1, -1, 0), Vec3(0.3, -1, -0.2)}) {
            const Vec3 d = direction.normalized();
            SCOPED_TRACE(d.transpose());
            const std::optional<QueryHit> near = agreed_ray(space, target - 10 * d, target + 10 * d);
            const std::optional<QueryHit> hit = agreed_ray(space, target - far * d, target + 1e3 * d);
            if (!near || !hit) {
                ADD_FAILURE() << "missed: a ten-metre ray " << near.has_value() << ", a billion-metre one "
                              << hit.has_value();
                continue;
            }
            EXPECT_EQ(hit->body, b);
            // A billion metres of ray holds its point to a few micrometres (1e9 x 2^-52 ~ 2e-7 m).
            EXPECT_LE((hit->point - near->point).norm(), 1e-5)
                << hit->point.transpose() << " vs " << near->point.transpose();
        }
        // Sweeps and overlaps across the same distances.
        const std::optional<QueryHit> sweep = space.cast_shape(Shape::sphere(0.1), {Vec3(0, far, 0), Quat::Identity()},
                                                               Vec3(0, -far, 0));
        EXPECT_TRUE(sweep.has_value());
        if (sweep) {
            EXPECT_NEAR(sweep->point.y(), top, 1e-5) << sweep->point.transpose();
        }
        std::vector<BodyHandle> found;
        EXPECT_EQ(space.overlap_box({Vec3(-far, -far, -far), Vec3(far, far, far)}, found), 1u);
    }
}

// A sweep that does not move is an overlap test at fraction 0.
TEST(OutsideQueries, ZeroTranslationSweepIsAnOverlapAtFractionZero) {
    Space space(still());
    const BodyHandle ball = space.create_body(body(Shape::sphere(1), Vec3::Zero()));
    space.create_body(body(test::flat_grid_mesh(4, 1), Vec3(0, -3, 0)));
    const std::optional<QueryHit> touching = space.cast_shape(Shape::box(Vec3(0.5, 0.5, 0.5)),
                                                              {Vec3(1.2, 0, 0), Quat::Identity()}, Vec3::Zero());
    ASSERT_TRUE(touching.has_value());
    EXPECT_EQ(touching->body, ball);
    EXPECT_EQ(touching->fraction, 0);
    EXPECT_FALSE(
        space.cast_shape(Shape::box(Vec3(0.5, 0.5, 0.5)), {Vec3(3, 0, 0), Quat::Identity()}, Vec3::Zero()).has_value());
    const std::optional<QueryHit> on_mesh = space.cast_shape(Shape::sphere(0.5),
                                                             {Vec3(0.3, -2.7, 0.2), Quat::Identity()}, Vec3::Zero());
    ASSERT_TRUE(on_mesh.has_value());
    EXPECT_EQ(on_mesh->fraction, 0);
}

// A filter's accept that throws: the query throws it, and the space queries on as before.
TEST(OutsideQueries, AFilterThatThrowsLeavesTheSpaceQueryable) {
    Space space(still());
    const BodyHandle ball = space.create_body(body(Shape::sphere(1), Vec3::Zero()));
    QueryFilter hostile;
    hostile.accept = [](BodyHandle) -> bool { throw std::runtime_error("the game's filter failed"); };
    std::vector<QueryHit> hits;
    std::vector<BodyHandle> bodies;
    EXPECT_THROW(space.cast_ray(Vec3(-5, 0, 0), Vec3(5, 0, 0), hostile), std::runtime_error);
    EXPECT_THROW(space.ray_hits_any(Vec3(-5, 0, 0), Vec3(5, 0, 0), hostile), std::runtime_error);
    EXPECT_THROW(space.cast_ray_all(Vec3(-5, 0, 0), Vec3(5, 0, 0), hits, hostile), std::runtime_error);
    EXPECT_THROW(space.cast_shape(Shape::sphere(0.1), {Vec3(-5, 0, 0), Quat::Identity()}, Vec3(10, 0, 0), hostile),
                 std::runtime_error);
    EXPECT_THROW(space.overlap_shape(Shape::sphere(2), {}, bodies, hostile), std::runtime_error);
    EXPECT_THROW(space.overlap_box({Vec3(-1, -1, -1), Vec3(1, 1, 1)}, bodies, hostile), std::runtime_error);
    // Nothing held: the space steps, changes and queries as before.
    for (int i = 0; i < 3; ++i) space.update();
    const BodyHandle box = space.create_body(body(Shape::box(Vec3(1, 1, 1)), Vec3(-4, 0, 0)));
    space.update();
    const std::optional<QueryHit> hit = agreed_ray(space, Vec3(-10, 0, 0), Vec3(10, 0, 0));
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->body, box);
    EXPECT_EQ(space.overlap_shape(Shape::sphere(2), {}, bodies), 1u);
    EXPECT_EQ(bodies.front(), ball);
}

// A filter's accept may itself query the space (a read, like any other).
TEST(OutsideQueries, AFilterThatQueriesTheSpaceAgainWorks) {
    Space space(still());
    const BodyHandle near = space.create_body(body(Shape::sphere(0.5), Vec3(-2, 0, 0)));
    const BodyHandle far = space.create_body(body(Shape::sphere(0.5), Vec3(2, 0, 0)));
    QueryFilter nested;
    // Accept only bodies that a ray straight down onto them also meets first.
    nested.accept = [&](BodyHandle b) {
        const Vec3 at = b == near ? Vec3(-2, 0, 0) : Vec3(2, 0, 0);
        const std::optional<QueryHit> down = space.cast_ray(at + Vec3(0, 5, 0), at);
        return down && down->body == b && b == far;
    };
    const std::optional<QueryHit> hit = agreed_ray(space, Vec3(-10, 0, 0), Vec3(10, 0, 0), nested);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->body, far);
}

// Filters by layer mask, group and ignore on overlaps and sweeps, as on rays.
TEST(OutsideQueries, EveryQueryFiltersByLayerGroupAndIgnore) {
    Space space(still());
    BodyDesc a = body(Shape::sphere(0.5), Vec3(-1, 0, 0));
    a.layer = 3;
    a.group = 5;
    BodyDesc b = body(Shape::box(Vec3(0.5, 0.5, 0.5)), Vec3(1, 0, 0));
    b.layer = 4;
    const BodyHandle ha = space.create_body(a);
    const BodyHandle hb = space.create_body(b);
    std::vector<BodyHandle> found;
    const Aabb everywhere{Vec3(-5, -5, -5), Vec3(5, 5, 5)};
    QueryFilter only3;
    only3.layer_mask = 1u << 3;
    EXPECT_EQ(space.overlap_box(everywhere, found, only3), 1u);
    EXPECT_EQ(found.front(), ha);
    EXPECT_EQ(space.overlap_shape(Shape::sphere(3), {}, found, only3), 1u);
    EXPECT_EQ(found.front(), ha);
    QueryFilter group5;
    group5.group = 5;
    EXPECT_EQ(space.overlap_box(everywhere, found, group5), 1u);
    EXPECT_EQ(found.front(), hb);
    const std::optional<QueryHit> sweep = space.cast_shape(Shape::sphere(0.1), {Vec3(-5, 0, 0), Quat::Identity()},
                                                           Vec3(10, 0, 0), group5);
    ASSERT_TRUE(sweep.has_value());
    EXPECT_EQ(sweep->body, hb);
    QueryFilter ignore_b;
    ignore_b.ignore = hb;
    ignore_b.layer_mask = 1u << 4;
    EXPECT_EQ(space.overlap_box(everywhere, found, ignore_b), 0u);
    EXPECT_FALSE(
        space.cast_shape(Shape::sphere(0.1), {Vec3(-5, 0, 0), Quat::Identity()}, Vec3(10, 0, 0), ignore_b).has_value());
    QueryFilter none;
    none.layer_mask = 0;
    EXPECT_FALSE(agreed_ray(space, Vec3(-5, 0, 0), Vec3(5, 0, 0), none).has_value());
}

// Hand-built query shapes are checked as create_body checks them.
TEST(OutsideQueries, HandBuiltQueryShapesAreCheckedNamingTheField) {
    Space space(still());
    space.create_body(body(Shape::sphere(1), Vec3::Zero()));
    std::vector<BodyHandle> found;
    Shape bad = Shape::sphere(1);
    bad.radius = std::nan("");
    EXPECT_NE(test::error_of([&] { space.overlap_shape(bad, {}, found); }).find("shape.radius"), std::string::npos);
    bad = Shape::box(Vec3(1, 1, 1));
    bad.half_extents.z() = -1;
    EXPECT_NE(test::error_of([&] { space.cast_shape(bad, {}, Vec3(1, 0, 0)); }).find("shape.half_extents"),
              std::string::npos);
    bad = Shape{};
    bad.type = ShapeType::Compound;
    EXPECT_NE(test::error_of([&] { space.overlap_shape(bad, {}, found); }).find("shape.parts"), std::string::npos);
    bad.type = ShapeType::ConvexHull;
    EXPECT_NE(test::error_of([&] { space.cast_shape(bad, {}, Vec3(1, 0, 0)); }).find("shape.hull"), std::string::npos);
    bad.type = static_cast<ShapeType>(42);
    EXPECT_NE(test::error_of([&] { space.overlap_shape(bad, {}, found); }).find("shape.type"), std::string::npos);
    EXPECT_NE(test::error_of([&] {
                  space.overlap_shape(Shape::sphere(1), {Vec3(2e9, 0, 0), Quat::Identity()}, found);
              }).find("pose.p"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] {
                  space.overlap_box({Vec3(0, 0, 0), Vec3(2e9, 1, 1)}, found);
              }).find("box.max"),
              std::string::npos);
}

// A compound as the query's own shape overlaps what any of its parts overlaps.
TEST(OutsideQueries, CompoundQueryShapeOverlapsWhatItsPartsOverlap) {
    Space space(still());
    const BodyHandle left = space.create_body(body(Shape::sphere(0.5), Vec3(-3, 0, 0)));
    const BodyHandle right = space.create_body(body(Shape::box(Vec3(0.5, 0.5, 0.5)), Vec3(3, 0, 0)));
    space.create_body(body(Shape::sphere(0.5), Vec3(0, 0, 0)));  // in the gap between the parts
    const CompoundPart parts[] = {{Shape::sphere(0.6), Vec3(-3, 0, 0), Quat::Identity()},
                                  {Shape::box(Vec3(0.6, 0.6, 0.6)), Vec3(3, 0, 0), Quat::Identity()}};
    std::vector<BodyHandle> found;
    const std::string message = test::error_of([&] { space.overlap_shape(Shape::compound(parts), {}, found); });
    if (message != "(no error)") {
        // Refused is fine, if it names why.
        EXPECT_NE(message.find("shape"), std::string::npos) << message;
        return;
    }
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(found[0], left);
    EXPECT_EQ(found[1], right);
    const std::optional<QueryHit> sweep = space.cast_shape(Shape::compound(parts), {Vec3(0, 5, 0), Quat::Identity()},
                                                           Vec3(0, -10, 0));
    ASSERT_TRUE(sweep.has_value());
}

}  // namespace spindle::outside_queries_test
