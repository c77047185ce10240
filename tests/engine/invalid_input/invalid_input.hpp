// The invalid-input suite's tools (after Box2D's test_invalid_input.c): the values every
// field is tried with, the rule a field follows, a small scene to try them on, and the
// check that a rejection names the field and changes nothing.
#pragma once

#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "static_bodies.hpp"

namespace spindle::test {

inline constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
inline constexpr Real kInf = std::numeric_limits<Real>::infinity();

// What a real-valued field accepts besides every finite positive value.
enum class Rule {
    Finite,       // any finite value (negative and zero too)
    NonNegative,  // finite and >= 0
    Positive,     // finite and > 0
};

struct Trial {
    const char* name;
    Real value;
};
// Every field is tried with each of these.
inline constexpr Trial kTrials[] = {{"nan", kNaN}, {"+inf", kInf}, {"-inf", -kInf}, {"negative", -1}, {"zero", 0}};

inline bool accepts(Rule rule, Real value) {
    if (!std::isfinite(value)) return false;
    switch (rule) {
        case Rule::Finite: return true;
        case Rule::NonNegative: return value >= 0;
        case Rule::Positive: return value > 0;
    }
    return false;
}

// The message of the spindle::Error that f throws, or "(accepted)".
inline std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(accepted)";
}

// A ground, a resting sphere, a falling box and a distance joint between them, after a
// few steps: bad input must leave every part of it alone.
struct Scene {
    std::unique_ptr<Space> space;
    BodyHandle ground, sphere, box;
    JointHandle joint;
};

inline Scene make_scene(const SpaceSettings& settings = {}) {
    Scene s;
    s.space = std::make_unique<Space>(settings);
    s.ground = test::add_static_box(*s.space, Vec3(10, 0.5, 10), Vec3(0, -0.5, 0));
    BodyDesc sphere;
    sphere.shape = Shape::sphere(0.5);
    sphere.position = Vec3(0, 0.5, 0);
    s.sphere = s.space->create_body(sphere);
    BodyDesc box;
    box.shape = Shape::box(Vec3(0.5, 0.25, 0.5));
    box.position = Vec3(2, 3, 0);
    box.linear_velocity = Vec3(1, 0, 0);
    box.angular_velocity = Vec3(0, 2, 0);
    s.box = s.space->create_body(box);
    JointDesc joint = JointDesc::distance_between(s.sphere, s.box, Vec3(0, 0.5, 0), Vec3(2, 3, 0));
    joint.distance.enable_spring = true;
    joint.distance.spring_hertz = 2;
    s.joint = s.space->create_joint(joint);
    for (int i = 0; i < 5; ++i) s.space->update();
    return s;
}

// `change` must throw a spindle::Error whose message holds `field`, and leave the space
// as it was: the same state hash and body and joint counts now, and after one more
// update the same state as `twin` (made like `space` and never touched), so nothing of
// the bad input was buffered or stored either.
inline void expect_rejected(Space& space, Space& twin, const std::function<void()>& change, const std::string& field,
                            const std::string& trial) {
    SCOPED_TRACE(field + " = " + trial);
    const std::uint64_t hash = space.state_hash();
    const std::size_t bodies = space.body_count();
    const std::size_t joints = space.joint_count();
    const std::string message = error_of(change);
    EXPECT_NE(message.find(field), std::string::npos) << "the message does not name " << field << ": " << message;
    EXPECT_EQ(space.state_hash(), hash);
    EXPECT_EQ(space.body_count(), bodies);
    EXPECT_EQ(space.joint_count(), joints);
    space.update();
    twin.update();
    EXPECT_EQ(space.state_hash(), twin.state_hash()) << "the rejected input changed the next update";
}

inline void expect_accepted(const std::function<void()>& change, const std::string& field, const std::string& trial) {
    SCOPED_TRACE(field + " = " + trial);
    EXPECT_EQ(error_of(change), "(accepted)");
}

}  // namespace spindle::test
