// Invalid input an outside tester tried: handles that never named a body, name one in
// another space or name a slot reused since; joints whose bodies became unable to hold
// them; finite but absurd sizes, anchors and targets. Each is refused naming what was
// wrong and changes nothing, or (where the API accepts it) leaves a finite state.
#include <spindle/engine/entity.hpp>
#include <spindle/engine/motion_state_manager.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace outside_input_test {

namespace {

// Every live body's internal state is finite (the engine's promise for any accepted input).
void expect_finite_state(const Space& space, const std::vector<BodyHandle>& bodies) {
    for (BodyHandle b : bodies) {
        if (!space.contains(b)) continue;
        const MotionState s = space.internal_motion_state(b);
        EXPECT_TRUE(s.position.allFinite() && s.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
                    s.angular_velocity.allFinite())
            << to_string(b) << " at " << s.position.transpose() << " v " << s.linear_velocity.transpose();
    }
}

// Every call that takes a body handle, each with the handle under test.
struct HandleCall {
    const char* name;
    std::function<void(Space&, BodyHandle)> call;
};

const std::vector<HandleCall>& handle_calls() {
    static const std::vector<HandleCall> calls{
        {"position", [](Space& s, BodyHandle b) { (void)s.position(b); }},
        {"motion_state", [](Space& s, BodyHandle b) { (void)s.motion_state(b); }},
        {"orientation", [](Space& s, BodyHandle b) { (void)s.orientation(b); }},
        {"center_of_mass", [](Space& s, BodyHandle b) { (void)s.center_of_mass(b); }},
        {"linear_velocity", [](Space& s, BodyHandle b) { (void)s.linear_velocity(b); }},
        {"angular_velocity", [](Space& s, BodyHandle b) { (void)s.angular_velocity(b); }},
        {"user_data", [](Space& s, BodyHandle b) { (void)s.user_data(b); }},
        {"set_position", [](Space& s, BodyHandle b) { s.set_position(b, Vec3(1, 2, 3)); }},
        {"set_orientation", [](Space& s, BodyHandle b) { s.set_orientation(b, Quat::Identity()); }},
        {"set_linear_velocity", [](Space& s, BodyHandle b) { s.set_linear_velocity(b, Vec3(1, 0, 0)); }},
        {"set_angular_velocity", [](Space& s, BodyHandle b) { s.set_angular_velocity(b, Vec3(1, 0, 0)); }},
        {"set_motion_state", [](Space& s, BodyHandle b) { s.set_motion_state(b, MotionState{}); }},
        {"add_force", [](Space& s, BodyHandle b) { s.add_force(b, Vec3(1, 0, 0)); }},
        {"add_torque", [](Space& s, BodyHandle b) { s.add_torque(b, Vec3(1, 0, 0)); }},
        {"apply_impulse", [](Space& s, BodyHandle b) { s.apply_impulse(b, Vec3(1, 0, 0)); }},
        {"apply_angular_impulse", [](Space& s, BodyHandle b) { s.apply_angular_impulse(b, Vec3(1, 0, 0)); }},
        {"wake", [](Space& s, BodyHandle b) { s.wake(b); }},
        {"set_collision_filter", [](Space& s, BodyHandle b) { s.set_collision_filter(b, 1, 2); }},
        {"set_friction", [](Space& s, BodyHandle b) { s.set_friction(b, 0.1); }},
        {"set_restitution", [](Space& s, BodyHandle b) { s.set_restitution(b, 0.1); }},
        {"set_rolling_resistance", [](Space& s, BodyHandle b) { s.set_rolling_resistance(b, 0.1); }},
        {"set_gravity_scale", [](Space& s, BodyHandle b) { s.set_gravity_scale(b, 2); }},
        {"set_damping", [](Space& s, BodyHandle b) { s.set_damping(b, 1, 1); }},
        {"set_motion_type", [](Space& s, BodyHandle b) { s.set_motion_type(b, MotionType::Static); }},
        {"set_shape", [](Space& s, BodyHandle b) { s.set_shape(b, Shape::sphere(0.25)); }},
        {"set_user_data", [](Space& s, BodyHandle b) { s.set_user_data(b, 9); }},
        {"add_force_at", [](Space& s, BodyHandle b) { s.add_force_at(b, Vec3(1, 0, 0), Vec3::Zero()); }},
        {"apply_impulse_at", [](Space& s, BodyHandle b) { s.apply_impulse_at(b, Vec3(1, 0, 0), Vec3::Zero()); }},
        {"move_kinematic", [](Space& s, BodyHandle b) { s.move_kinematic(b, Vec3::Zero(), Quat::Identity()); }},
        {"destroy_body", [](Space& s, BodyHandle b) { s.destroy_body(b); }},
        {"internal_motion_state", [](Space& s, BodyHandle b) { (void)s.internal_motion_state(b); }},
        {"internal_position", [](Space& s, BodyHandle b) { (void)s.internal_position(b); }},
        {"internal_orientation", [](Space& s, BodyHandle b) { (void)s.internal_orientation(b); }},
        {"internal_linear_velocity", [](Space& s, BodyHandle b) { (void)s.internal_linear_velocity(b); }},
        {"internal_angular_velocity", [](Space& s, BodyHandle b) { (void)s.internal_angular_velocity(b); }},
        {"set_internal_motion_state", [](Space& s, BodyHandle b) { s.set_internal_motion_state(b, MotionState{}); }},
        {"internal_is_awake", [](Space& s, BodyHandle b) { (void)s.internal_is_awake(b); }},
        {"internal_desc", [](Space& s, BodyHandle b) { (void)s.internal_desc(b); }},
        {"get_motion_states",
         [](Space& s, BodyHandle b) {
             MotionState out[1];
             s.motion_states().get_motion_states(std::span<const BodyHandle>(&b, 1), out);
         }},
        {"get_raw_motion_states",
         [](Space& s, BodyHandle b) {
             MotionState out[1];
             s.motion_states().get_raw_motion_states(std::span<const BodyHandle>(&b, 1), out);
         }},
        {"read", [](Space& s, BodyHandle b) { (void)s.motion_states().read(b); }},
        {"create_joint a",
         [](Space& s, BodyHandle b) {
             s.create_joint(JointDesc::ball_socket_at(b, BodyHandle{1, 1}, Vec3::Zero()));
         }},
        {"create_joint b",
         [](Space& s, BodyHandle b) {
             s.create_joint(JointDesc::ball_socket_at(BodyHandle{1, 1}, b, Vec3::Zero()));
         }},
    };
    return calls;
}

// Every handle call with `bad` on the invalid-input scene: refused naming the handle,
// and nothing changed (now, and after the next update against an untouched twin).
void expect_every_call_refuses(BodyHandle bad, const std::string& what,
                               const std::function<void(Scene&)>& prepare = {}) {
    for (const HandleCall& c : handle_calls()) {
        Scene scene = make_scene();
        Scene twin = make_scene();
        if (prepare) {
            prepare(scene);
            prepare(twin);
        }
        expect_rejected(
            *scene.space, *twin.space, [&] { c.call(*scene.space, bad); }, to_string(bad),
            std::string(c.name) + " with a " + what + " handle");
    }
}

}  // namespace

// Handles no body ever had: generation 0, a slot past every slot made, the largest values.
TEST(OutsideInput, HandlesThatNeverNamedABodyAreRefusedEverywhere) {
    for (BodyHandle bad : {BodyHandle{0, 0}, BodyHandle{1, 0}, BodyHandle{3, 1}, BodyHandle{1000000, 1},
                           BodyHandle{~0u, ~0u}, BodyHandle{~0u, 1}, BodyHandle{0, 2}}) {
        expect_every_call_refuses(bad, "never valid");
    }
}

// A handle whose slot was freed and given to a new body names the old body only.
TEST(OutsideInput, HandleToASlotReusedSinceIsRefusedEverywhere) {
    BodyHandle old{};
    expect_every_call_refuses(BodyHandle{1, 1}, "reused slot", [&](Scene& s) {
        // The sphere (slot 1, generation 1) goes; a new body takes its slot.
        s.space->destroy_body(s.sphere);
        BodyDesc d;
        d.position = Vec3(-2, 1, 0);
        const BodyHandle reborn = s.space->create_body(d);
        EXPECT_EQ(reborn.index, 1u);
        EXPECT_NE(reborn.generation, 1u);
        old = s.sphere;
        s.space->update();
    });
    EXPECT_EQ(old, (BodyHandle{1, 1}));
}

// A handle from a space with more bodies names no body here.
TEST(OutsideInput, HandleFromAnotherSpaceIsRefused) {
    Space other;
    BodyHandle foreign{};
    for (int i = 0; i < 6; ++i) foreign = other.create_body(BodyDesc{});
    ASSERT_EQ(foreign.index, 5u);
    expect_every_call_refuses(foreign, "foreign");
}

// Joint calls with handles to joints destroyed with their body, never made, or reused.
TEST(OutsideInput, JointHandlesOfDestroyedBodiesAndNeverMadeJointsAreRefused) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    auto joint_of_removed_body = [](Scene& s) {
        // The box goes, and its joint with it; a new joint takes the joint's slot.
        s.space->destroy_body(s.box);
        BodyDesc d;
        d.position = Vec3(3, 1, 0);
        const BodyHandle c = s.space->create_body(d);
        s.space->create_joint(JointDesc::ball_socket_at(s.sphere, c, Vec3(1.5, 1, 0)));
        s.space->update();
    };
    joint_of_removed_body(scene);
    joint_of_removed_body(twin);
    EXPECT_FALSE(scene.space->contains(scene.joint));
    const std::vector<std::pair<const char*, std::function<void(Space&, JointHandle)>>> calls{
        {"destroy_joint", [](Space& s, JointHandle j) { s.destroy_joint(j); }},
        {"joint_desc", [](Space& s, JointHandle j) { (void)s.joint_desc(j); }},
        {"set_hinge_motor", [](Space& s, JointHandle j) { s.set_hinge_motor(j, true, 1, 1); }},
        {"set_motor_target", [](Space& s, JointHandle j) { s.set_motor_target(j, Vec3::Zero(), Quat::Identity()); }},
        {"set_mouse_target", [](Space& s, JointHandle j) { s.set_mouse_target(j, Vec3::Zero()); }},
        {"internal_joint_error", [](Space& s, JointHandle j) { (void)s.internal_joint_error(j); }},
        {"internal_hinge_angle", [](Space& s, JointHandle j) { (void)s.internal_hinge_angle(j); }},
    };
    for (JointHandle bad : {scene.joint, JointHandle{0, 0}, JointHandle{7, 1}, JointHandle{~0u, ~0u}}) {
        for (const auto& [name, call] : calls) {
            expect_rejected(
                *scene.space, *twin.space, [&] { call(*scene.space, bad); }, to_string(bad), std::string(name));
        }
    }
}

// Joint calls that do not fit the joint's type: refused, naming the joint and its type.
TEST(OutsideInput, JointCallsForAnotherTypeAreRefused) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    const std::string joint = to_string(scene.joint);
    expect_rejected(
        *scene.space, *twin.space, [&] { scene.space->set_hinge_motor(scene.joint, true, 1, 1); }, joint,
        "set_hinge_motor on a distance joint");
    expect_rejected(
        *scene.space, *twin.space, [&] { scene.space->set_motor_target(scene.joint, Vec3::Zero(), Quat::Identity()); },
        joint, "set_motor_target on a distance joint");
    expect_rejected(
        *scene.space, *twin.space, [&] { scene.space->set_mouse_target(scene.joint, Vec3::Zero()); }, joint,
        "set_mouse_target on a distance joint");
    expect_rejected(
        *scene.space, *twin.space, [&] { (void)scene.space->internal_hinge_angle(scene.joint); }, joint,
        "internal_hinge_angle on a distance joint");
}

// Anchors are points on the bodies: one a billion kilometres away is no anchor a game
// means; it must be refused as positions are (or, if taken, leave a finite state).
TEST(OutsideInput, AnchorsFarBeyondTheWorldAreRefusedOrHarmless) {
    for (JointFrame frame : {JointFrame::World, JointFrame::Local}) {
        for (Real far : {1e12, 1e200, 1e300}) {
            for (JointType type : {JointType::BallSocket, JointType::Hinge, JointType::Fixed, JointType::Distance,
                                   JointType::Prismatic, JointType::SwingTwist, JointType::Motor}) {
                SCOPED_TRACE(std::string(to_string(type)) + (frame == JointFrame::World ? " world " : " local ") +
                             std::to_string(far));
                Scene scene = make_scene();
                Scene twin = make_scene();
                JointDesc d = JointDesc::ball_socket_at(scene.ground, scene.box, Vec3(2, 3, 0));
                d.type = type;
                d.anchors.frame = frame;
                d.anchors.b = Vec3(far, 0, 0);
                d.motor.max_force = 100;
                const std::string message = error_of([&] { scene.space->create_joint(d); });
                if (message == "(accepted)") {
                    for (int i = 0; i < 60; ++i) scene.space->update();
                    expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
                } else {
                    EXPECT_NE(message.find("anchors.b"), std::string::npos) << message;
                    EXPECT_EQ(scene.space->joint_count(), 1u);
                    scene.space->update();
                    twin.space->update();
                    EXPECT_EQ(scene.space->state_hash(), twin.space->state_hash());
                }
            }
        }
    }
}

// Finite targets and lengths as large as a double holds: the joint may not reach them,
// but the bodies stay finite (speeds are held to the solver's limits).
TEST(OutsideInput, HugeJointTargetsLengthsAndMotorsLeaveAFiniteState) {
    for (const Real huge : {1e9, 1e300}) {
        SCOPED_TRACE(huge);
        std::vector<std::function<JointDesc(Scene&)>> joints{
            [&](Scene& s) {
                JointDesc d = JointDesc::distance_between(s.ground, s.box, Vec3(0, 0, 0), Vec3(2, 3, 0));
                d.distance.rest_length = huge;
                d.distance.max_length = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::distance_between(s.ground, s.box, Vec3(0, 0, 0), Vec3(2, 3, 0));
                d.distance.enable_spring = true;
                d.distance.spring_hertz = huge;
                d.distance.spring_damping_ratio = huge;
                d.distance.rest_length = huge;
                d.distance.max_length = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::prismatic_at(s.ground, s.box, Vec3(2, 3, 0), Vec3(1, 0, 0));
                d.prismatic.enable_spring = true;
                d.prismatic.spring_hertz = huge;
                d.prismatic.target_translation = huge;
                d.prismatic.enable_motor = true;
                d.prismatic.motor_speed = huge;
                d.prismatic.max_motor_force = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::prismatic_at(s.ground, s.box, Vec3(2, 3, 0), Vec3(1, 0, 0));
                d.prismatic.enable_limit = true;
                d.prismatic.lower_translation = huge;
                d.prismatic.upper_translation = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::hinge_at(s.ground, s.box, Vec3(2, 3, 0), Vec3(0, 0, 1));
                d.hinge.enable_motor = true;
                d.hinge.motor_speed = huge;
                d.hinge.max_motor_torque = huge;
                d.hinge.limit_spring_hertz = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::motor_between(s.ground, s.box, Vec3(2, 3, 0));
                d.motor.linear_offset = Vec3(huge, 0, 0);
                d.motor.max_force = huge;
                d.motor.max_torque = huge;
                d.motor.linear_hertz = huge;
                d.motor.angular_hertz = huge;
                d.motor.linear_damping_ratio = huge;
                return d;
            },
            [&](Scene& s) {
                JointDesc d = JointDesc::swing_twist_at(s.ground, s.box, Vec3(2, 3, 0), Vec3(0, 1, 0));
                d.swing_twist.max_friction_torque = huge;
                return d;
            },
        };
        for (std::size_t k = 0; k < joints.size(); ++k) {
            SCOPED_TRACE("joint " + std::to_string(k));
            Scene scene = make_scene();
            const std::string message = error_of([&] { scene.space->create_joint(joints[k](scene)); });
            if (huge <= 1e9) {
                EXPECT_EQ(message, "(accepted)") << "within the world's bound";
            }
            if (message != "(accepted)") {
                EXPECT_NE(message.find("create_joint: "), std::string::npos) << message;  // refused, naming the field
                continue;
            }
            scene.space->apply_impulse(scene.box, Vec3(0, 50, 10));
            for (int i = 0; i < 60; ++i) scene.space->update();
            expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
        }
    }
}

// Motor and mouse targets as large as a double holds.
// set_hinge_motor as create_joint: a speed past the bound is refused, naming it.
TEST(OutsideInput, HingeMotorSpeedBeyondTheBoundIsRefused) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    auto hinge = [](Scene& s) {
        return s.space->create_joint(JointDesc::hinge_at(s.ground, s.box, Vec3(2, 3, 0), Vec3(0, 0, 1)));
    };
    const JointHandle j = hinge(scene);
    hinge(twin);
    expect_rejected(
        *scene.space, *twin.space, [&] { scene.space->set_hinge_motor(j, true, 1e300, 1e300); },
        "set_hinge_motor: speed", "1e300");
    scene.space->set_hinge_motor(j, true, 1e9, 1e300);
    for (int i = 0; i < 30; ++i) scene.space->update();
    expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
}

TEST(OutsideInput, HugeMotorAndMouseTargetsLeaveAFiniteState) {
    Scene scene = make_scene();
    JointDesc motor = JointDesc::motor_between(scene.ground, scene.box, Vec3(2, 3, 0));
    motor.motor.max_force = 1e6;
    motor.motor.max_torque = 1e6;
    const JointHandle m = scene.space->create_joint(motor);
    const JointHandle mouse =
        scene.space->create_joint(JointDesc::mouse_at(scene.ground, scene.sphere, Vec3(0, 0.5, 0), 5, 1, 1e6));
    const std::string a = error_of([&] { scene.space->set_motor_target(m, Vec3(1e300, 0, 0), Quat::Identity()); });
    const std::string b = error_of([&] { scene.space->set_mouse_target(mouse, Vec3(0, -1e300, 0)); });
    for (int i = 0; i < 60; ++i) scene.space->update();
    expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
    if (a != "(accepted)") {
        EXPECT_NE(a.find("linear_offset"), std::string::npos) << a;
    }
    if (b != "(accepted)") {
        EXPECT_NE(b.find("target"), std::string::npos) << b;
    }
}

// A joint needs one dynamic body; making its dynamic body static or kinematic later
// leaves a joint between two bodies that cannot move. The step must stay finite, and
// the joint must hold again when the body is made dynamic once more.
TEST(OutsideInput, JointWhoseDynamicBodyIsMadeStaticOrKinematicLeavesAFiniteState) {
    for (MotionType to : {MotionType::Static, MotionType::Kinematic}) {
        for (JointType type : {JointType::BallSocket, JointType::Hinge, JointType::Fixed, JointType::Distance,
                               JointType::Prismatic, JointType::SwingTwist, JointType::Motor}) {
            SCOPED_TRACE(std::string(to_string(type)) +
                         (to == MotionType::Static ? " made static" : " made kinematic"));
            Scene scene = make_scene();
            JointDesc d = JointDesc::ball_socket_at(scene.ground, scene.box, Vec3(2, 3.5, 0));
            d.type = type;
            d.motor.max_force = 100;
            d.distance.rest_length = 1;
            const JointHandle j = scene.space->create_joint(d);
            scene.space->set_motion_type(scene.box, to);
            scene.space->set_motion_type(scene.sphere, to);  // the distance joint's two bodies too
            for (int i = 0; i < 30; ++i) scene.space->update();
            expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
            EXPECT_TRUE(scene.space->contains(j));
            scene.space->set_motion_type(scene.box, MotionType::Dynamic);
            scene.space->set_motion_type(scene.sphere, MotionType::Dynamic);
            for (int i = 0; i < 30; ++i) scene.space->update();
            expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
        }
    }
}

// Shapes with finite but absurd sizes: refused naming the shape, or a finite state.
TEST(OutsideInput, AbsurdShapeSizesAreRefusedOrHarmless) {
    struct Case {
        const char* name;
        MotionType type;
        Shape shape;
    };
    const std::vector<Case> cases{
        {"static sphere 1e300", MotionType::Static, Shape::sphere(1e300)},
        {"static box 1e300", MotionType::Static, Shape::box(Vec3(1e300, 1e300, 1e300))},
        {"static box 1e308", MotionType::Static, Shape::box(Vec3(1e308, 1, 1e308))},
        {"static capsule 1e300", MotionType::Static, Shape::capsule(1e300, 1e300)},
        {"kinematic box 1e300", MotionType::Kinematic, Shape::box(Vec3(1e300, 1, 1))},
        {"dynamic sphere 1e300", MotionType::Dynamic, Shape::sphere(1e300)},
        {"dynamic sphere 1e100", MotionType::Dynamic, Shape::sphere(1e100)},
        {"dynamic sphere 1e-100", MotionType::Dynamic, Shape::sphere(1e-100)},
        {"dynamic box 1e-200", MotionType::Dynamic, Shape::box(Vec3(1e-200, 1, 1))},
        {"dynamic capsule thin", MotionType::Dynamic, Shape::capsule(1, 1e-200)},
        {"dynamic sphere 1e-300", MotionType::Dynamic, Shape::sphere(1e-300)},
        {"static plane offset 1e300", MotionType::Static, Shape::plane(Vec3(0, 1, 0), 1e300)},
        {"static plane offset -1e300", MotionType::Static, Shape::plane(Vec3(0, 1, 0), -1e300)},
        {"dynamic compound of a huge box", MotionType::Dynamic,
         Shape::compound(std::vector<CompoundPart>{{Shape::box(Vec3(1e300, 1, 1)), Vec3::Zero(), Quat::Identity()}})},
        {"static compound of a huge sphere", MotionType::Static,
         Shape::compound(std::vector<CompoundPart>{{Shape::sphere(1e300), Vec3::Zero(), Quat::Identity()}})},
        // At the bound: taken, and the scene stays finite.
        {"static sphere 1e9", MotionType::Static, Shape::sphere(1e9)},
        {"static box 1e9", MotionType::Static, Shape::box(Vec3(1e9, 1e9, 1e9))},
        {"static plane offset -1e9", MotionType::Static, Shape::plane(Vec3(0, 1, 0), -1e9)},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        Scene scene = make_scene();
        Scene twin = make_scene();
        BodyDesc d;
        d.type = c.type;
        d.shape = c.shape;
        d.position = Vec3(0, -2, 0);
        BodyHandle made{};
        const std::string message = error_of([&] { made = scene.space->create_body(d); });
        if (message == "(accepted)") {
            for (int i = 0; i < 30; ++i) scene.space->update();
            expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box, made});
            std::vector<QueryHit> hits;
            scene.space->cast_ray_all(Vec3(0, 10, 0), Vec3(0, -10, 0), hits);
            for (const QueryHit& h : hits) EXPECT_TRUE(std::isfinite(h.fraction) && h.point.allFinite());
        } else {
            // Named by the shape's field, or by the mass it would have.
            EXPECT_TRUE(message.find("shape") != std::string::npos || message.find("mass") != std::string::npos)
                << message;
            scene.space->update();
            twin.space->update();
            EXPECT_EQ(scene.space->state_hash(), twin.space->state_hash());
        }
        // The same through set_shape on the falling box (as of its motion type).
        Scene again = make_scene();
        const BodyHandle target = c.type == MotionType::Static ? again.ground : again.box;
        if (c.type == MotionType::Kinematic) again.space->set_motion_type(target, MotionType::Kinematic);
        again.space->update();
        const std::string changed = error_of([&] { again.space->set_shape(target, c.shape); });
        for (int i = 0; i < 30; ++i) again.space->update();
        expect_finite_state(*again.space, {again.ground, again.sphere, again.box});
        if (changed != "(accepted)") {
            EXPECT_TRUE(changed.find("shape") != std::string::npos || changed.find("mass") != std::string::npos)
                << changed;
        }
    }
}

// The factories of shapes with points refuse points past the positions' bound, naming
// the point (a hull at 1e300 m was "collinear": its plane tests overflowed).
TEST(OutsideInput, ShapeFactoriesRefusePointsBeyondTheBound) {
    const std::string hull = error_of([] {
        (void)Shape::convex_hull(std::vector<Vec3>{{-1e300, 0, 0}, {1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}});
    });
    EXPECT_NE(hull.find("point 0 must be within 1e+09 m of the origin"), std::string::npos) << hull;
    const std::string mesh = error_of([] {
        (void)Shape::triangle_mesh(std::vector<Vec3>{{-1, 0, -1}, {1, 0, -1}, {0, 0, 2e9}},
                                   std::vector<std::uint32_t>{0, 2, 1});
    });
    EXPECT_NE(mesh.find("vertex 2 must be within 1e+09 m of the origin"), std::string::npos) << mesh;
    const std::string compound = error_of([] {
        (void)Shape::compound(std::vector<CompoundPart>{{Shape::sphere(1), Vec3::Zero(), Quat::Identity()},
                                                        {Shape::sphere(1), Vec3(0, -1e300, 0), Quat::Identity()}});
    });
    EXPECT_NE(compound.find("part 1: position must be within 1e+09 m"), std::string::npos) << compound;
    // At the bound they are taken.
    EXPECT_EQ(error_of([] {
                  (void)Shape::convex_hull(std::vector<Vec3>{{-1e9, 0, 0}, {1e9, 0, 0}, {0, 1e9, 0}, {0, 0, 1e9}});
              }),
              "(accepted)");
}

// An Entity whose body the game destroyed through the space (its handle now stale) is
// not stuck in the space: removing it lets it go (nothing live to copy back), and it can
// be added again, to this space or another.
TEST(OutsideInput, EntityWhoseBodyWasDestroyedThroughTheSpaceCanBeRemovedAndAddedAgain) {
    Space space;
    BodyDesc d;
    d.position = Vec3(1, 2, 3);
    Entity entity(d);
    entity.add_to(space);
    const BodyHandle first = entity.handle();
    space.destroy_body(first);
    EXPECT_NE(error_of([&] { (void)entity.position(); }).find(to_string(first)), std::string::npos);
    const std::string removed = error_of([&] { entity.remove_from_space(); });
    EXPECT_EQ(removed, "(accepted)");
    EXPECT_FALSE(entity.in_space());
    EXPECT_EQ(entity.position(), Vec3(1, 2, 3));  // as it was added
    Space other;
    entity.add_to(other);
    EXPECT_TRUE(other.contains(entity.handle()));
    entity.remove_from_space();
    entity.add_to(space);
    EXPECT_TRUE(space.contains(entity.handle()));
    EXPECT_NE(entity.handle(), first);
}

// Mass and density as large or small as a double holds.
TEST(OutsideInput, AbsurdMassAndDensityAreRefusedOrHarmless) {
    struct Case {
        Real mass, density;
        Real radius;
    };
    for (const Case& c : {Case{1e300, 1000, 0.5}, Case{1e-300, 1000, 0.5}, Case{0, 1e300, 0.5}, Case{0, 1e-300, 0.5},
                          Case{0, 1e300, 1e3}, Case{1, 1e300, 1e3}, Case{1e300, 1000, 1e-100},
                          Case{1e-300, 1000, 1e100}, Case{1, 1000, 1e-150}, Case{1, 1000, 1e150}}) {
        SCOPED_TRACE("mass " + std::to_string(c.mass) + " density " + std::to_string(c.density) + " radius " +
                     std::to_string(c.radius));
        Scene scene = make_scene();
        Scene twin = make_scene();
        BodyDesc d;
        d.mass = c.mass;
        d.density = c.density;
        d.shape = Shape::sphere(c.radius);
        d.position = Vec3(0, 1.6, 0);  // on the resting sphere
        BodyHandle made{};
        const std::string message = error_of([&] { made = scene.space->create_body(d); });
        if (message == "(accepted)") {
            scene.space->apply_impulse(made, Vec3(1, 0, 0));
            for (int i = 0; i < 30; ++i) scene.space->update();
            expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box, made});
        } else {
            EXPECT_TRUE(message.find("mass") != std::string::npos || message.find("density") != std::string::npos ||
                        message.find("shape") != std::string::npos)
                << message;
            scene.space->update();
            twin.space->update();
            EXPECT_EQ(scene.space->state_hash(), twin.space->state_hash());
        }
    }
}

// Time steps as small or large as a double holds, set while the accumulator holds time.
TEST(OutsideInput, AbsurdStepDurationsKeepTheClockFinite) {
    for (Real duration : {1e-300, 1e-30, 1e30, 1e300}) {
        SCOPED_TRACE(duration);
        Scene scene = make_scene();
        TimeStepSettings t;
        t.use_internal_time_stepping = true;
        t.duration = 1.0 / 60;
        scene.space->set_time_step(t);
        scene.space->update(0.01);
        t.duration = duration;
        const std::string message = error_of([&] { scene.space->set_time_step(t); });
        if (message != "(accepted)") {
            EXPECT_NE(message.find("duration"), std::string::npos) << message;
            continue;
        }
        for (int i = 0; i < 3; ++i) scene.space->update(1.0 / 60);
        scene.space->update(1e6);
        EXPECT_TRUE(std::isfinite(scene.space->accumulated_time())) << scene.space->accumulated_time();
        EXPECT_TRUE(std::isfinite(scene.space->last_update().dropped_seconds));
        expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
    }
}

// Settings with values no scene means (but finite and in range): a finite state.
TEST(OutsideInput, AbsurdSolverAndSleepSettingsLeaveAFiniteState) {
    std::vector<std::function<void(SpaceSettings&)>> spoil{
        [](SpaceSettings& s) { s.solver.max_linear_speed = 1e300; },
        [](SpaceSettings& s) { s.solver.max_angular_speed = 1e300; },
        [](SpaceSettings& s) { s.solver.max_linear_speed = 1e-300; },
        [](SpaceSettings& s) { s.solver.contact_hertz = 1e300; },
        [](SpaceSettings& s) { s.solver.damping_ratio = 1e300; },
        [](SpaceSettings& s) { s.solver.joint_hertz = 1e300; },
        [](SpaceSettings& s) { s.solver.joint_damping_ratio = 1e300; },
        [](SpaceSettings& s) { s.solver.push_out_speed = 1e300; },
        [](SpaceSettings& s) { s.solver.recovery_depth = 1e300; },
        [](SpaceSettings& s) { s.solver.speculative_distance = 1e300; },
        [](SpaceSettings& s) { s.solver.linear_slop = 1e300; },
        [](SpaceSettings& s) { s.solver.restitution_threshold = 1e300; },
        [](SpaceSettings& s) { s.sleep.time_to_sleep = 1e300; },
        [](SpaceSettings& s) { s.sleep.linear_threshold = 1e300; },
        [](SpaceSettings& s) { s.events.hit_speed = 1e300; },
        [](SpaceSettings& s) { s.gravity = Vec3(0, -1e300, 0); },
    };
    for (std::size_t k = 0; k < spoil.size(); ++k) {
        SCOPED_TRACE("setting " + std::to_string(k));
        SpaceSettings settings;
        spoil[k](settings);
        Scene scene = make_scene(settings);
        scene.space->apply_impulse(scene.box, Vec3(1e5, 0, 0));
        for (int i = 0; i < 30; ++i) scene.space->update();
        expect_finite_state(*scene.space, {scene.ground, scene.sphere, scene.box});
    }
}

}  // namespace outside_input_test
