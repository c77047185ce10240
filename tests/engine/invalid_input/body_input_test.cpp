// Invalid bodies: every BodyDesc field and every field of a hand-built shape, for every
// motion type, through create_body; and every shape factory. A rejection names the field
// and leaves the space unchanged.
#include <array>
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

constexpr std::array<MotionType, 3> kMotionTypes{MotionType::Static, MotionType::Kinematic, MotionType::Dynamic};

const char* name_of(MotionType type) {
    return type == MotionType::Static ? "static" : type == MotionType::Kinematic ? "kinematic" : "dynamic";
}

BodyDesc body_of(MotionType type) {
    BodyDesc d;
    d.type = type;
    d.position = Vec3(-3, 1, 2);
    return d;
}

// create_body(desc) on a fresh scene: accepted, or rejected naming `field` with nothing changed.
void try_body(const BodyDesc& desc, bool accepted, const std::string& field, const std::string& trial) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    auto create = [&] { scene.space->create_body(desc); };
    const std::string what = std::string(name_of(desc.type)) + " body, " + trial;
    if (accepted) {
        expect_accepted(create, field, what);
    } else {
        expect_rejected(*scene.space, *twin.space, create, field, what);
    }
}

}  // namespace

TEST(InvalidBody, VectorFieldsMustBeFinite) {
    const std::vector<std::pair<const char*, Vec3 BodyDesc::*>> fields{
        {"position", &BodyDesc::position},
        {"linear_velocity", &BodyDesc::linear_velocity},
        {"angular_velocity", &BodyDesc::angular_velocity},
    };
    for (MotionType type : kMotionTypes) {
        for (const auto& [name, member] : fields) {
            for (int axis = 0; axis < 3; ++axis) {
                for (const Trial& t : kTrials) {
                    BodyDesc d = body_of(type);
                    (d.*member)[axis] = t.value;
                    try_body(d, accepts(Rule::Finite, t.value), name, t.name);
                }
            }
        }
    }
}

TEST(InvalidBody, OrientationMustBeFiniteAndNonZero) {
    for (MotionType type : kMotionTypes) {
        for (int k = 0; k < 4; ++k) {
            for (const Trial& t : kTrials) {
                BodyDesc d = body_of(type);
                d.orientation.coeffs()[k] = t.value;
                // Zero in w (coefficient 3) leaves the identity all zero: the zero quaternion.
                const bool ok = accepts(Rule::Finite, t.value) && !(k == 3 && t.value == 0);
                try_body(d, ok, "orientation", t.name);
            }
        }
        BodyDesc d = body_of(type);
        d.orientation = Quat(0, 0, 0, 0);
        try_body(d, false, "orientation", "zero");
    }
}

TEST(InvalidBody, RealFieldsFollowTheirRules) {
    for (MotionType type : kMotionTypes) {
        // Density is used (and must be > 0) only by a dynamic body whose mass is 0.
        const Rule density = type == MotionType::Dynamic ? Rule::Positive : Rule::NonNegative;
        const std::vector<std::tuple<const char*, Real BodyDesc::*, Rule>> fields{
            {"density", &BodyDesc::density, density},
            {"mass", &BodyDesc::mass, Rule::NonNegative},
            {"friction", &BodyDesc::friction, Rule::NonNegative},
            {"restitution", &BodyDesc::restitution, Rule::NonNegative},
            {"rolling_resistance", &BodyDesc::rolling_resistance, Rule::NonNegative},
            {"gravity_scale", &BodyDesc::gravity_scale, Rule::Finite},
            {"linear_damping", &BodyDesc::linear_damping, Rule::NonNegative},
            {"angular_damping", &BodyDesc::angular_damping, Rule::NonNegative},
        };
        for (const auto& [name, member, rule] : fields) {
            for (const Trial& t : kTrials) {
                BodyDesc d = body_of(type);
                d.*member = t.value;
                try_body(d, accepts(rule, t.value), name, t.name);
            }
        }
    }
}

TEST(InvalidBody, LayerMustBeBelowTheLayerCount) {
    for (MotionType type : kMotionTypes) {
        for (std::uint32_t layer : {0u, kLayerCount - 1, kLayerCount, 1000u, ~0u}) {
            BodyDesc d = body_of(type);
            d.layer = layer;
            d.group = ~0u;  // any group is valid
            try_body(d, layer < kLayerCount, "layer", std::to_string(layer));
        }
    }
}

TEST(InvalidBody, MotionTypeOutOfRangeIsRejected) {
    BodyDesc d = body_of(MotionType::Dynamic);
    d.type = static_cast<MotionType>(7);
    try_body(d, false, "type", "7");
}

// Shapes built by hand (the fields are public) are checked again by create_body.
TEST(InvalidBody, HandBuiltShapesAreCheckedForEveryMotionType) {
    for (MotionType type : kMotionTypes) {
        for (const Trial& t : kTrials) {
            const bool ok = accepts(Rule::Positive, t.value);
            BodyDesc d = body_of(type);
            d.shape = Shape{};
            d.shape.type = ShapeType::Sphere;
            d.shape.radius = t.value;
            try_body(d, ok, "shape.radius", std::string("sphere ") + t.name);

            d.shape = Shape::capsule(0.5, 0.25);
            d.shape.radius = t.value;
            try_body(d, ok, "shape.radius", std::string("capsule ") + t.name);
            d.shape = Shape::capsule(0.5, 0.25);
            d.shape.half_height = t.value;
            try_body(d, ok, "shape.half_height", std::string("capsule ") + t.name);

            for (int axis = 0; axis < 3; ++axis) {
                d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
                d.shape.half_extents[axis] = t.value;
                try_body(d, ok, "shape.half_extents", std::string("box ") + t.name);
            }
        }
        BodyDesc d = body_of(type);
        d.shape = Shape{};
        d.shape.type = ShapeType::ConvexHull;
        try_body(d, false, "shape.hull", "missing");
        d.shape.type = static_cast<ShapeType>(9);
        try_body(d, false, "shape.type", "9");
        d.shape.type = ShapeType::Count;
        try_body(d, false, "shape.type", "Count");
    }
}

TEST(InvalidBody, HandBuiltStaticShapesAreChecked) {
    for (const Trial& t : kTrials) {
        for (int axis = 0; axis < 3; ++axis) {
            BodyDesc d = body_of(MotionType::Static);
            d.shape = Shape::plane(Vec3(1, 1, 1), 0);
            d.shape.normal[axis] = t.value;  // the other two keep it non-zero
            try_body(d, accepts(Rule::Finite, t.value), "shape.normal", t.name);
        }
        BodyDesc d = body_of(MotionType::Static);
        d.shape = Shape::plane(Vec3::UnitY(), 0);
        d.shape.offset = t.value;
        try_body(d, accepts(Rule::Finite, t.value), "shape.offset", t.name);
    }
    BodyDesc d = body_of(MotionType::Static);
    d.shape = Shape::plane(Vec3::UnitY(), 0);
    d.shape.normal = Vec3::Zero();
    try_body(d, false, "shape.normal", "zero");
    d.shape = Shape{};
    d.shape.type = ShapeType::TriangleMesh;
    try_body(d, false, "shape.mesh", "missing");
}

TEST(InvalidBody, MessageNamesTheShapeFieldAndValue) {
    Space space;
    BodyDesc d;
    d.shape.radius = kNaN;
    EXPECT_EQ(error_of([&] { space.create_body(d); }), "create_body: shape.radius must be finite and > 0, got nan");
    d.shape = Shape::box(Vec3(1, 1, 1));
    d.shape.half_extents.y() = -1;
    EXPECT_EQ(error_of([&] { space.create_body(d); }),
              "create_body: shape.half_extents must be finite and > 0, got (1, -1, 1)");
    EXPECT_EQ(space.body_count(), 0u);
}

// The factories check their own input, naming the field.
TEST(InvalidBody, ShapeFactoriesRejectBadValues) {
    for (const Trial& t : kTrials) {
        SCOPED_TRACE(t.name);
        const bool positive = accepts(Rule::Positive, t.value);
        auto check = [&](bool ok, const std::function<void()>& make, const std::string& field) {
            const std::string message = error_of(make);
            if (ok) {
                EXPECT_EQ(message, "(accepted)") << field;
            } else {
                EXPECT_NE(message.find(field), std::string::npos) << message;
            }
        };
        check(
            positive, [&] { Shape::sphere(t.value); }, "radius");
        check(
            positive, [&] { Shape::capsule(t.value, 1); }, "half_height");
        check(
            positive, [&] { Shape::capsule(1, t.value); }, "radius");
        for (int axis = 0; axis < 3; ++axis) {
            Vec3 e(1, 1, 1);
            e[axis] = t.value;
            check(
                positive, [&] { Shape::box(e); }, "half_extents");
            Vec3 n(1, 1, 1);
            n[axis] = t.value;
            check(
                accepts(Rule::Finite, t.value), [&] { Shape::plane(n, 0); }, "normal");
            // The other four points span a volume whatever point 3 becomes.
            std::vector<Vec3> points{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 1), Vec3(0, 0, 1)};
            points[3][axis] = t.value;
            check(
                accepts(Rule::Finite, t.value), [&] { Shape::convex_hull(points); }, "point 3");
            // The second triangle stays whatever vertex 2 becomes (a zero-area triangle is dropped).
            std::vector<Vec3> vertices{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0)};
            vertices[2][axis] = t.value;
            const std::vector<std::uint32_t> indices{0, 1, 2, 0, 1, 3};
            check(
                accepts(Rule::Finite, t.value), [&] { Shape::triangle_mesh(vertices, indices); }, "vertex 2");
            // A compound's part position, and its orientation's coefficients (any finite
            // non-zero quaternion is normalised; zero in one coefficient leaves it non-zero).
            std::vector<CompoundPart> parts(2, CompoundPart{Shape::sphere(1), Vec3::Zero(), Quat::Identity()});
            parts[1].position[axis] = t.value;
            check(
                accepts(Rule::Finite, t.value), [&] { Shape::compound(parts); }, "part 1: position");
            parts[1].position = Vec3::Zero();
            parts[1].orientation.coeffs()[axis] = t.value;
            check(
                accepts(Rule::Finite, t.value), [&] { Shape::compound(parts); }, "part 1: orientation");
        }
        // A part's size, set by hand (the factory would reject it first).
        Shape ball;
        ball.type = ShapeType::Sphere;
        ball.radius = t.value;
        const std::vector<CompoundPart> one{{ball, Vec3::Zero(), Quat::Identity()}};
        check(
            positive, [&] { Shape::compound(one); }, "part 0: sphere radius");
        check(
            accepts(Rule::Finite, t.value), [&] { Shape::plane(Vec3::UnitY(), t.value); }, "offset");
        check(
            false, [&] { Shape::plane(Vec3::Zero(), 0); }, "normal");
    }
}
