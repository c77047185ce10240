// Pairs whose fat boxes overlap but whose shapes are too far apart for any contact point
// are ruled out from their bounds (narrowphase.cpp, out_of_reach): no collision test and
// no read of the contact record.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

using namespace spindle;

namespace out_of_reach_test {

namespace {

SpaceSettings weightless() {
    SpaceSettings s;
    s.sleep.enabled = false;
    s.gravity = Vec3::Zero();
    return s;
}

BodyHandle add(Space& space, const Shape& shape, const Vec3& p, const Vec3& v = Vec3::Zero()) {
    BodyDesc d;
    d.shape = shape;
    d.position = p;
    d.linear_velocity = v;
    return space.create_body(d);
}

// Surfaces 0.1 m apart: the fat boxes (0.02 m speculative and a 0.05 m margin each) overlap,
// the speculative distance (4 cm) is far short.
constexpr Real kGap = 0.1;

}  // namespace

TEST(OutOfReach, FarPairsWithARoundShapeAreNotCollided) {
    Space space(weightless());
    add(space, Shape::sphere(0.4), Vec3(0, 0, 0));
    add(space, Shape::sphere(0.4), Vec3(0.8 + kGap, 0, 0));
    add(space, Shape::capsule(0.3, 0.4), Vec3(0, 5, 0));
    add(space, Shape::box(Vec3::Constant(0.4)), Vec3(0.8 + kGap, 5, 0));
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().contacts_updated, 20u);
    EXPECT_EQ(space.counters().contacts_out_of_reach, 20u);
    EXPECT_EQ(space.counters().manifolds_reused, 0u);
    EXPECT_EQ(space.last_update().contacts, 0u);
}

// Two polyhedra too, lined up or turned: their bounds' gap is a distance no point of theirs
// comes within.
TEST(OutOfReach, FarPolyhedraAreNotCollided) {
    Space space(weightless());
    add(space, Shape::box(Vec3::Constant(0.4)), Vec3(0, 0, 0));
    add(space, Shape::box(Vec3::Constant(0.4)), Vec3(0.8 + kGap, 0, 0));
    const Quat tilt = Quat(Eigen::AngleAxis<Real>(0.6, Vec3::UnitZ())) *
                      Quat(Eigen::AngleAxis<Real>(0.7, Vec3::UnitY()));
    BodyDesc d;
    d.shape = Shape::box(Vec3::Constant(0.4));
    d.orientation = tilt;
    d.position = Vec3(0, 5, 0);
    space.create_body(d);
    d.orientation = tilt.conjugate();
    d.position = Vec3(0, 5, 0) + Vec3(1.474, 0, 0);  // bounds 0.1 m apart along x
    space.create_body(d);
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(space.counters().contacts_updated, 20u);
    EXPECT_EQ(space.counters().contacts_out_of_reach, 20u);
    EXPECT_EQ(space.counters().manifolds_reused, 0u);
    EXPECT_EQ(space.last_update().contacts, 0u);
}

// The reach counts how far the pair closes in one step: spheres kGap apart, out of reach
// at rest, closing at 24 m/s (0.4 m a step) are tested, and the speculative contact stops
// them before they overlap.
TEST(OutOfReach, ApproachingSpheresAreTestedInTime) {
    Space space(weightless());
    const BodyHandle a = add(space, Shape::sphere(0.4), Vec3(0, 0, 0));
    const BodyHandle b = add(space, Shape::sphere(0.4), Vec3(0.8 + kGap, 0, 0));
    space.update();
    ASSERT_EQ(space.counters().contacts_out_of_reach, 1u);
    space.set_linear_velocity(a, Vec3(12, 0, 0));
    space.set_linear_velocity(b, Vec3(-12, 0, 0));
    for (int i = 0; i < 5; ++i) {
        space.update();
        const Real distance = space.internal_position(b).x() - space.internal_position(a).x();
        ASSERT_GT(distance, 0.8 - 0.02) << "step " << i;
    }
    EXPECT_EQ(space.counters().contacts_out_of_reach, 1u);
    EXPECT_GT(space.last_update().contacts, 0u);
    EXPECT_LT(space.internal_linear_velocity(a).x(), 1.0);  // stopped
}

// A pair that reports events is ruled out as any other (events must not change the
// simulation), and its touch is still reported when the pair comes near.
TEST(OutOfReach, ReportingPairsAreRuledOutAlike) {
    SpaceSettings settings = weightless();
    settings.gravity = Vec3(10, 0, 0);  // falls sideways onto the static one
    Space space(settings);
    BodyDesc d;
    d.shape = Shape::sphere(0.4);
    d.contact_events = true;
    space.create_body(d);
    d.type = MotionType::Static;
    d.position = Vec3(0.8 + 0.06, 0, 0);  // a static proxy is not fattened: closer, so the pair is found
    space.create_body(d);
    space.update();
    EXPECT_EQ(space.counters().contacts_updated, 1u);
    EXPECT_EQ(space.counters().contacts_out_of_reach, 1u);
    std::vector<ContactEvent> events;
    EXPECT_EQ(space.read_contact_events(events), 0u);
    for (int i = 0; i < 30; ++i) space.update();
    bool began = false;
    space.read_contact_events(events);
    for (const ContactEvent& e : events) began = began || e.kind == ContactEventKind::Begin;
    EXPECT_TRUE(began);
}

}  // namespace out_of_reach_test
