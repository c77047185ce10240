// Bad compounds are rejected with an error naming the part and what was wrong.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "compound_test_util.hpp"

namespace spindle {
namespace {

using namespace test;

constexpr Real kNan = std::numeric_limits<Real>::quiet_NaN();
constexpr Real kInf = std::numeric_limits<Real>::infinity();

std::string compound_error(const std::vector<CompoundPart>& parts) {
    return error_of([&] { Shape::compound(parts); });
}

CompoundPart good() { return {Shape::box(Vec3(0.2, 0.2, 0.2)), Vec3::Zero(), Quat::Identity()}; }

void expect_mentions(const std::string& message, const std::string& a, const std::string& b) {
    EXPECT_NE(message.find(a), std::string::npos) << message;
    EXPECT_NE(message.find(b), std::string::npos) << message;
}

TEST(CompoundInput, EmptyCompoundIsRejected) { expect_mentions(compound_error({}), "compound", "at least one part"); }

TEST(CompoundInput, PlaneMeshAndNestedCompoundPartsAreRejected) {
    const Vec3 vertices[] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
    const std::uint32_t indices[] = {0, 1, 2};
    const Shape not_convex[] = {Shape::plane(Vec3::UnitY(), 0), Shape::triangle_mesh(vertices, indices),
                                Shape::compound(std::vector<CompoundPart>{good()})};
    for (const Shape& shape : not_convex) {
        const std::string message = compound_error({good(), {shape, Vec3::Zero(), Quat::Identity()}});
        expect_mentions(message, "part 1", to_string(shape.type));
    }
}

TEST(CompoundInput, PartsOfZeroVolumeAreRejected) {
    // Built field by field: the factories would reject these themselves.
    Shape sphere;
    sphere.type = ShapeType::Sphere;
    sphere.radius = 0;
    Shape box = Shape::box(Vec3(0.2, 0.2, 0.2));
    box.half_extents.y() = 0;
    Shape capsule = Shape::capsule(0.5, 0.1);
    capsule.radius = -1;
    Shape hull;
    hull.type = ShapeType::ConvexHull;
    expect_mentions(compound_error({{sphere, Vec3::Zero(), Quat::Identity()}}), "part 0", "sphere radius");
    expect_mentions(compound_error({good(), good(), {box, Vec3::Zero(), Quat::Identity()}}), "part 2",
                    "half_extents.y must be positive and finite (a part needs volume), got 0");
    expect_mentions(compound_error({{capsule, Vec3::Zero(), Quat::Identity()}}), "part 0", "got -1");
    expect_mentions(compound_error({{hull, Vec3::Zero(), Quat::Identity()}}), "part 0", "hull");
}

TEST(CompoundInput, NonFinitePositionsAndBadOrientationsAreRejected) {
    for (const Real bad : {kNan, kInf, -kInf}) {
        CompoundPart part = good();
        part.position.z() = bad;
        expect_mentions(compound_error({good(), part}), "part 1", "position must be finite");
        part = good();
        part.orientation = Quat(1, bad, 0, 0);
        expect_mentions(compound_error({part}), "part 0", "orientation must be finite and non-zero");
    }
    CompoundPart zero = good();
    zero.orientation = Quat(0, 0, 0, 0);
    expect_mentions(compound_error({zero}), "part 0", "got (0, 0, 0, 0)");
}

TEST(CompoundInput, RejectedCompoundLeavesTheSpaceAsItWas) {
    Space space;
    BodyDesc d;
    d.shape = dumbbell();
    space.create_body(d);
    const std::uint64_t before = space.state_hash();
    CompoundPart bad = good();
    bad.position.x() = kNan;
    EXPECT_FALSE(compound_error({bad}).empty());
    // A compound body without parts (built field by field) is rejected by create_body.
    Shape hollow;
    hollow.type = ShapeType::Compound;
    d.shape = hollow;
    expect_mentions(error_of([&] { space.create_body(d); }), "create_body", "shape.parts");
    EXPECT_EQ(space.body_count(), 1u);
    EXPECT_EQ(space.state_hash(), before);
}

}  // namespace
}  // namespace spindle
