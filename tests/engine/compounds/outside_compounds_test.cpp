// Compounds as an outside tester tried them: a body of many parts resting on a mesh and
// named part by part by rays, the response of a body of turned, offset parts to an
// impulse against its parts' summed inertia, and orientations given with components as
// large or small as a double holds.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace spindle::outside_compounds_test {
namespace {

std::string error_text(const std::function<void()>& call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "(accepted)";
}

}  // namespace

// 5 x 5 x 3 balls of radius 0.1, touching, as one body (75 parts, turned): a ray down
// each column names the column's top part and meets it on its surface, and a sphere
// cast down the same column stops on it.
TEST(OutsideCompounds, RaysAndSweepsNameEachOfManyParts) {
    std::vector<CompoundPart> parts;
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            for (int z = 0; z < 5; ++z) {
                parts.push_back({Shape::sphere(0.1), Vec3(0.2 * (x - 2), 0.2 * y, 0.2 * (z - 2)), Quat::Identity()});
            }
        }
    }
    Space space;
    BodyDesc d;
    d.type = MotionType::Kinematic;
    d.shape = Shape::compound(parts);
    d.position = Vec3(0.05, 0.6, -0.05);
    d.orientation = Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitY()));
    const BodyHandle b = space.create_body(d);
    space.update();
    for (int x = 0; x < 5; ++x) {
        for (int z = 0; z < 5; ++z) {
            const Vec3 top = d.position + d.orientation * Vec3(0.2 * (x - 2), 0.4, 0.2 * (z - 2));
            const std::optional<QueryHit> hit = space.cast_ray(top + Vec3(0, 2, 0), top);
            ASSERT_TRUE(hit.has_value());
            EXPECT_EQ(hit->body, b);
            EXPECT_EQ(hit->part, static_cast<std::uint32_t>(2 * 25 + x * 5 + z)) << x << ", " << z;
            EXPECT_NEAR(hit->point.y(), top.y() + 0.1, 1e-12);
            const std::optional<QueryHit> sweep =
                space.cast_shape(Shape::sphere(0.02), {top + Vec3(0, 2, 0), Quat::Identity()}, Vec3(0, -2, 0));
            ASSERT_TRUE(sweep.has_value());
            EXPECT_EQ(sweep->part, hit->part);
            EXPECT_NEAR(sweep->point.y(), top.y() + 0.1, 1e-5);  // the cast's tolerance (cast.cpp)
        }
    }
}

// A flat slab of 3 x 3, 4 x 4 and 5 x 5 balls dropped flat on the ground settles and
// sleeps. At ff39273 the 16- and 25-ball slabs rocked for ever (|w| ~ 1 rad/s after 4 s):
// a contact keeps at most kMaxContactManifolds (8) manifolds, and emit()
// (collide_compound.cpp) kept the 8 that ranked deepest, the balls on the side sinking
// most: the slab was held on one side only, tipped, and the other side then ranked
// deeper, step after step. Now half are the deepest and the rest the farthest apart.
TEST(OutsideCompounds, FlatSlabsOfManyBallsComeToRestOnTheGround) {
    for (int n : {3, 4, 5}) {
        SCOPED_TRACE(std::to_string(n * n) + " balls");
        std::vector<CompoundPart> parts;
        for (int x = 0; x < n; ++x) {
            for (int z = 0; z < n; ++z)
                parts.push_back({Shape::sphere(0.1), Vec3(0.2 * x, 0, 0.2 * z), Quat::Identity()});
        }
        Space space;
        BodyDesc ground;
        ground.type = MotionType::Static;
        ground.shape = Shape::plane(Vec3::UnitY(), 0);
        space.create_body(ground);
        BodyDesc d;
        d.shape = Shape::compound(parts);
        d.position = Vec3(0, 0.3, 0);
        const BodyHandle b = space.create_body(d);
        for (int i = 0; i < 240; ++i) space.update();  // 4 s: 3 x 3 sleeps within 2
        EXPECT_FALSE(space.internal_is_awake(b));
        EXPECT_LT(space.internal_angular_velocity(b).norm(), 0.01);
        EXPECT_NEAR(space.internal_position(b).y(), 0.1, 0.01);
    }
}

// An angular impulse on a body of turned, offset parts turns it at I^-1 L, with I the
// compound's inertia (non-diagonal) turned by the body's orientation.
TEST(OutsideCompounds, AngularImpulseTurnsABodyOfTurnedPartsByItsSummedInertia) {
    const CompoundPart parts[] = {
        {Shape::box(Vec3(0.6, 0.1, 0.2)), Vec3(0.3, 0, 0), Quat(Eigen::AngleAxis<Real>(0.7, Vec3(0, 0, 1)))},
        {Shape::capsule(0.4, 0.1), Vec3(-0.2, 0.3, 0.1), Quat(Eigen::AngleAxis<Real>(1.1, Vec3(1, 0, 0)))},
        {Shape::sphere(0.25), Vec3(0, -0.4, 0.5), Quat::Identity()},
    };
    const Shape shape = Shape::compound(parts);
    const MassProperties mp = shape.mass_properties(1000);
    ASSERT_GT(std::abs(mp.inertia(0, 1)) + std::abs(mp.inertia(1, 2)), 1e-3) << "not a non-diagonal inertia";
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    Space space(settings);
    BodyDesc d;
    d.shape = shape;
    d.density = 1000;
    d.orientation = Quat(Eigen::AngleAxis<Real>(0.9, Vec3(1, 2, 3).normalized()));
    d.position = Vec3(1, 2, 3);
    const BodyHandle b = space.create_body(d);
    space.update();
    // The centre of mass is where the parts' sum puts it, under the body's pose.
    const Vec3 com = d.position + d.orientation * mp.center_of_mass;
    EXPECT_LT((space.center_of_mass(b) - com).norm(), 1e-12);
    const Vec3 L(0.3, -0.2, 0.5);
    space.apply_angular_impulse(b, L);
    space.update();
    const Mat3 R = d.orientation.toRotationMatrix();
    const Vec3 expected = (R * mp.inertia * R.transpose()).inverse() * L;
    // One step turns the body by a few milliradians: its world inertia changes by as
    // much, and the velocity read after the step carries that (no gyroscopic term: the
    // angular momentum's direction stays, the velocity follows the turned inertia).
    EXPECT_LT((space.internal_angular_velocity(b) - expected).norm(), 0.02 * expected.norm())
        << space.internal_angular_velocity(b).transpose() << " vs " << expected.transpose();
    EXPECT_LT((space.center_of_mass(b) - com).norm(), 1e-12) << "a pure turn moves the centre of mass";
}

// A quaternion is normalised at creation whatever its scale: components as large as a
// double holds (whose squared norm overflows) are a turn like any other, or refused
// naming the orientation; never a zero or NaN orientation that spoils the step.
TEST(OutsideCompounds, OrientationsOfAnyScaleAreNormalisedOrRefused) {
    const Quat huge(1e300, 1e300, 0, 0);  // a half turn about x, scaled
    const Quat unit = Quat(1, 1, 0, 0).normalized();
    const CompoundPart parts[] = {{Shape::box(Vec3(0.5, 0.1, 0.2)), Vec3(0, 0.5, 0), huge},
                                  {Shape::sphere(0.2), Vec3::Zero(), Quat::Identity()}};
    const std::string part_error = error_text([&] { (void)Shape::compound(parts); });
    if (part_error == "(accepted)") {
        const CompoundPart unit_parts[] = {{Shape::box(Vec3(0.5, 0.1, 0.2)), Vec3(0, 0.5, 0), unit},
                                           {Shape::sphere(0.2), Vec3::Zero(), Quat::Identity()}};
        const MassProperties a = Shape::compound(parts).mass_properties(1000);
        const MassProperties b = Shape::compound(unit_parts).mass_properties(1000);
        EXPECT_TRUE(a.inertia.allFinite()) << a.inertia;
        EXPECT_LT((a.inertia - b.inertia).cwiseAbs().maxCoeff(), 1e-9) << a.inertia << "\nvs\n" << b.inertia;
    } else {
        EXPECT_NE(part_error.find("orientation"), std::string::npos) << part_error;
    }
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    Space space(settings);
    BodyDesc d;
    d.shape = Shape::box(Vec3(0.5, 0.1, 0.2));
    d.orientation = huge;
    BodyHandle body{};
    const std::string body_error = error_text([&] { body = space.create_body(d); });
    if (body_error == "(accepted)") {
        space.update();
        EXPECT_TRUE(space.internal_orientation(body).isApprox(unit, 1e-12))
            << space.internal_orientation(body).coeffs().transpose();
    } else {
        EXPECT_NE(body_error.find("orientation"), std::string::npos) << body_error;
        EXPECT_EQ(space.body_count(), 0u);
    }
    // The same through a write and a query pose.
    const BodyHandle other = space.create_body(BodyDesc{});
    const std::string write_error = error_text([&] { space.set_orientation(other, huge); });
    space.update();
    if (write_error == "(accepted)") {
        EXPECT_TRUE(space.internal_orientation(other).isApprox(unit, 1e-12))
            << space.internal_orientation(other).coeffs().transpose();
    } else {
        EXPECT_NE(write_error.find("orientation"), std::string::npos) << write_error;
    }
    std::vector<BodyHandle> found;
    const std::string query_error = error_text([&] {
        space.overlap_shape(Shape::box(Vec3(0.5, 0.1, 0.2)), {Vec3(0, 0, 0), huge}, found);
    });
    if (query_error != "(accepted)") {
        EXPECT_NE(query_error.find("pose.q"), std::string::npos) << query_error;
    }
    EXPECT_TRUE(space.internal_orientation(other).coeffs().allFinite());
}

}  // namespace spindle::outside_compounds_test
