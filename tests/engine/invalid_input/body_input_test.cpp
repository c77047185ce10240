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

// The solver keeps masses in single precision: a dynamic body whose mass or principal
// inertias leave [kMinMass, kMaxMass] is refused (a hull of 10 nm made the state NaN when it
// touched the floor: its inverse inertia overflowed a float). As a static or kinematic body
// it has no mass and is accepted.
TEST(InvalidBody, MassesOutOfTheSolversRangeAreRefused) {
    const Real legs = 1e-8;
    const std::vector<Vec3> speck{Vec3(0, 0, 0), Vec3(legs, 0, 0), Vec3(0, legs, 0), Vec3(0, 0, legs)};
    for (MotionType type : kMotionTypes) {
        const bool dynamic = type == MotionType::Dynamic;
        BodyDesc d = body_of(type);
        d.shape = Shape::convex_hull(speck);
        try_body(d, !dynamic, "principal inertias", "a hull of 10 nm");
        d.shape = Shape::sphere(1e5);  // 4e18 kg, 2e28 kg m^2 at water's density
        try_body(d, !dynamic, "principal inertias", "a sphere of 100 km");
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.mass = 1e25;
        try_body(d, !dynamic, "mass", "1e25 kg");
        d.mass = 1e-30;
        try_body(d, !dynamic, "mass", "1e-30 kg");
    }
    // What a game holds is in range: a 1 mm grain, a 10 km sphere, a metre box of 1e24 kg.
    BodyDesc d = body_of(MotionType::Dynamic);
    d.shape = Shape::sphere(1e-3);
    try_body(d, true, "mass", "a 1 mm grain");
    d.shape = Shape::sphere(1e4);
    try_body(d, true, "mass", "a sphere of 10 km");
    d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
    d.mass = 1e24;  // the range's top (stages/body_changes.hpp)
    try_body(d, true, "mass", "1e24 kg");
}

// Bodies at the ends of that range fall onto a floor and come to rest with a finite state.
TEST(InvalidBody, BodiesAtTheEndsOfTheMassRangeStayFinite) {
    Space space;
    test::add_static_box(space, Vec3(20, 1, 20), Vec3(0, -1, 0));
    std::vector<BodyHandle> bodies;
    const auto add = [&](const Shape& shape, Real mass, const Vec3& position) {
        BodyDesc d;
        d.shape = shape;
        d.mass = mass;
        d.position = position;
        d.angular_velocity = Vec3(1, 2, 3);
        bodies.push_back(space.create_body(d));
    };
    const Real legs = 1e-5;  // the smallest hull of the range at water's density: inertias ~1e-24
    add(Shape::convex_hull(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(legs, 0, 0), Vec3(0, legs, 0), Vec3(0, 0, legs)}), 0,
        Vec3(0, 0.01, 0));
    add(Shape::sphere(1e-3), 0, Vec3(1, 0.01, 0));
    add(Shape::box(Vec3(0.5, 0.5, 0.5)), 1e24, Vec3(3, 0.6, 0));
    add(Shape::box(Vec3(0.5, 0.5, 0.5)), 1e-20, Vec3(3, 1.7, 0));  // a feather on the heavy box
    for (int i = 0; i < 120; ++i) space.update();
    for (BodyHandle body : bodies) {
        EXPECT_TRUE(space.position(body).allFinite()) << to_string(body);
        EXPECT_TRUE(space.linear_velocity(body).allFinite()) << to_string(body);
        EXPECT_TRUE(space.angular_velocity(body).allFinite()) << to_string(body);
        EXPECT_GT(space.position(body).y(), -0.01) << to_string(body) << " fell through the floor";
    }
}

// Friction, restitution and rolling resistance take any finite value >= 0; the solver keeps a
// pair's in floats, where 1e300 is infinite: a box resting with friction 1e300 went NaN, and
// one dropped with restitution 1e30 was hurled 1e27 m by its bounce's warm start. Now the
// states stay finite and a bounce keeps to the speed limit.
TEST(InvalidBody, HugeMaterialCoefficientsKeepTheStateFinite) {
    SpaceSettings settings;
    Space space(settings);
    test::add_static_box(space, Vec3(20, 1, 20), Vec3(0, -1, 0));
    const auto add = [&](const Vec3& position, Real friction, Real restitution, Real rolling) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
        d.position = position;
        d.friction = friction;
        d.restitution = restitution;
        d.rolling_resistance = rolling;
        return space.create_body(d);
    };
    const BodyHandle resting = add(Vec3(0, 0.5, 0), 1e300, 0, 0);
    const BodyHandle sliding = add(Vec3(4, 0.5, 0), 1e300, 0, 1e300);
    space.set_linear_velocity(sliding, Vec3(3, 0, 0));
    const BodyHandle bouncing = add(Vec3(-4, 3, 0), 0.6, 1e30, 0);
    const BodyHandle wilder = add(Vec3(-8, 3, 0), 0.6, 1e300, 0);
    const Real limit = settings.solver.max_linear_speed;
    const int steps = 90;
    for (int i = 0; i < steps; ++i) space.update();
    for (BodyHandle body : {resting, sliding, bouncing, wilder}) {
        EXPECT_TRUE(space.position(body).allFinite()) << to_string(body);
        EXPECT_TRUE(space.angular_velocity(body).allFinite()) << to_string(body);
        EXPECT_LE(space.linear_velocity(body).norm(), limit) << to_string(body);
        // No further than the speed limit carries it in the run's 1.5 s.
        EXPECT_LE(space.position(body).norm(), 10 + limit * steps / 60.0) << to_string(body);
    }
    EXPECT_NEAR(space.position(resting).y(), 0.5, 0.01);  // friction holds, it does not move
    EXPECT_LT(std::abs(space.position(sliding).x() - 4), 0.1) << "friction 1e300 stops a slide at once";
}
