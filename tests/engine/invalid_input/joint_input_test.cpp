// Invalid joints: every JointDesc field of every joint type through create_joint, and
// set_hinge_motor. A rejection names the field and leaves the space unchanged.
#include <functional>
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

// A joint that uses every field of its type: limits, motor and spring on.
JointDesc joint_of(JointType type, const Scene& s) {
    JointDesc d = JointDesc::ball_socket_at(s.sphere, s.box, Vec3(1, 1, 0));
    d.type = type;
    d.hinge.enable_limit = true;
    d.hinge.lower_angle = -0.5;
    d.hinge.upper_angle = 0.5;
    d.hinge.enable_motor = true;
    d.hinge.motor_speed = 1;
    d.hinge.max_motor_torque = 10;
    d.distance.rest_length = 2;
    d.distance.enable_spring = true;
    d.distance.spring_hertz = 3;
    d.distance.spring_damping_ratio = 0.5;
    d.distance.enable_limit = true;
    d.distance.min_length = 0;
    d.distance.max_length = 5;
    d.swing_twist.twist_axis_a = d.swing_twist.twist_axis_b = Vec3(0, 1, 0);
    d.swing_twist.cone_half_angle = 0.5;
    d.swing_twist.twist_min = -0.25;
    d.swing_twist.twist_max = 0.25;
    d.swing_twist.max_friction_torque = 2;
    return d;
}

void try_joint(JointType type, const std::function<void(JointDesc&)>& spoil, bool accepted, const std::string& field,
               const std::string& trial) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    JointDesc d = joint_of(type, scene);
    spoil(d);
    auto create = [&] { scene.space->create_joint(d); };
    const std::string what = std::string(to_string(type)) + ", " + trial;
    if (accepted) {
        expect_accepted(create, field, what);
    } else {
        expect_rejected(*scene.space, *twin.space, create, field, what);
    }
}

using Spoil = std::function<void(JointDesc&, Real)>;

}  // namespace

TEST(InvalidJoint, AnchorsMustBeFiniteForEveryType) {
    for (JointType type :
         {JointType::BallSocket, JointType::Hinge, JointType::Fixed, JointType::Distance, JointType::SwingTwist}) {
        for (const char* field : {"anchors.a", "anchors.b"}) {
            for (int axis = 0; axis < 3; ++axis) {
                for (const Trial& t : kTrials) {
                    const bool on_a = field[8] == 'a';
                    try_joint(
                        type, [&](JointDesc& d) { (on_a ? d.anchors.a : d.anchors.b)[axis] = t.value; },
                        accepts(Rule::Finite, t.value), field, t.name);
                }
            }
        }
    }
}

TEST(InvalidJoint, TypeAndFrameOutOfRangeAreRejected) {
    try_joint(
        JointType::BallSocket, [](JointDesc& d) { d.type = static_cast<JointType>(9); }, false, "type", "9");
    try_joint(
        JointType::BallSocket, [](JointDesc& d) { d.anchors.frame = static_cast<JointFrame>(5); }, false,
        "anchors.frame", "5");
}

TEST(InvalidJoint, HingeFieldsFollowTheirRules) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const Trial& t : kTrials) {
            // axis_a and axis_b stay the same axis (a world-frame hinge needs that), non-zero.
            try_joint(
                JointType::Hinge,
                [&](JointDesc& d) {
                    d.hinge.axis_a = Vec3(1, 1, 1);
                    d.hinge.axis_a[axis] = t.value;
                    d.hinge.axis_b = d.hinge.axis_a;
                },
                accepts(Rule::Finite, t.value), "hinge.axis_a", t.name);
            try_joint(
                JointType::Hinge,
                [&](JointDesc& d) {
                    // In the Local frame each body has its own axis, so axis_b may differ.
                    d.anchors = JointAnchors::local(Vec3::Zero(), Vec3::Zero());
                    d.hinge.axis_b = Vec3(1, 1, 1);
                    d.hinge.axis_b[axis] = t.value;
                },
                accepts(Rule::Finite, t.value), "hinge.axis_b", t.name);
        }
    }
    try_joint(
        JointType::Hinge, [](JointDesc& d) { d.hinge.axis_a = d.hinge.axis_b = Vec3::Zero(); }, false, "hinge.axis_a",
        "zero");
    const std::vector<std::tuple<const char*, Real HingeParams::*, Rule>> fields{
        {"hinge.lower_angle", &HingeParams::lower_angle, Rule::Finite},       // -1 and 0 are within [-pi, upper]
        {"hinge.upper_angle", &HingeParams::upper_angle, Rule::NonNegative},  // -1 is below lower_angle
        {"hinge.motor_speed", &HingeParams::motor_speed, Rule::Finite},
        {"hinge.max_motor_torque", &HingeParams::max_motor_torque, Rule::NonNegative},
    };
    for (const auto& [field, member, rule] : fields) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Hinge, [&](JointDesc& d) { d.hinge.*member = t.value; }, accepts(rule, t.value), field,
                t.name);
        }
    }
}

TEST(InvalidJoint, DistanceFieldsFollowTheirRules) {
    const std::vector<std::tuple<const char*, Real DistanceParams::*, Rule>> fields{
        {"distance.rest_length", &DistanceParams::rest_length, Rule::Finite},  // negative: measured at creation
        {"distance.spring_hertz", &DistanceParams::spring_hertz, Rule::NonNegative},
        {"distance.spring_damping_ratio", &DistanceParams::spring_damping_ratio, Rule::NonNegative},
        {"distance.min_length", &DistanceParams::min_length, Rule::NonNegative},
        {"distance.max_length", &DistanceParams::max_length, Rule::NonNegative},  // min_length is 0
    };
    for (const auto& [field, member, rule] : fields) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Distance, [&](JointDesc& d) { d.distance.*member = t.value; }, accepts(rule, t.value), field,
                t.name);
        }
    }
}

TEST(InvalidJoint, SwingTwistFieldsFollowTheirRules) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::SwingTwist,
                [&](JointDesc& d) {
                    d.swing_twist.twist_axis_a = Vec3(1, 1, 1);
                    d.swing_twist.twist_axis_a[axis] = t.value;
                    d.swing_twist.twist_axis_b = d.swing_twist.twist_axis_a;
                },
                accepts(Rule::Finite, t.value), "swing_twist.twist_axis_a", t.name);
            try_joint(
                JointType::SwingTwist,
                [&](JointDesc& d) {
                    d.anchors = JointAnchors::local(Vec3::Zero(), Vec3::Zero());
                    d.swing_twist.twist_axis_b = Vec3(1, 1, 1);
                    d.swing_twist.twist_axis_b[axis] = t.value;
                },
                accepts(Rule::Finite, t.value), "swing_twist.twist_axis_b", t.name);
        }
    }
    try_joint(
        JointType::SwingTwist,
        [](JointDesc& d) { d.swing_twist.twist_axis_a = d.swing_twist.twist_axis_b = Vec3::Zero(); }, false,
        "swing_twist.twist_axis_a", "zero");
    const std::vector<std::tuple<const char*, Real SwingTwistParams::*, Rule>> fields{
        {"swing_twist.cone_half_angle", &SwingTwistParams::cone_half_angle, Rule::NonNegative},
        {"swing_twist.twist_min", &SwingTwistParams::twist_min, Rule::Finite},       // -1 and 0 are within [-pi, max]
        {"swing_twist.twist_max", &SwingTwistParams::twist_max, Rule::NonNegative},  // -1 is below twist_min
        {"swing_twist.max_friction_torque", &SwingTwistParams::max_friction_torque, Rule::NonNegative},
    };
    for (const auto& [field, member, rule] : fields) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::SwingTwist, [&](JointDesc& d) { d.swing_twist.*member = t.value; }, accepts(rule, t.value),
                field, t.name);
        }
    }
    // Angles beyond their range, and a twist range upside down.
    try_joint(
        JointType::SwingTwist, [](JointDesc& d) { d.swing_twist.cone_half_angle = 3.2; }, false,
        "swing_twist.cone_half_angle", "3.2");
    try_joint(
        JointType::SwingTwist, [](JointDesc& d) { d.swing_twist.cone_half_angle = kPi; }, true,
        "swing_twist.cone_half_angle", "pi");
    try_joint(
        JointType::SwingTwist, [](JointDesc& d) { d.swing_twist.twist_min = -3.2; }, false, "swing_twist.twist_min",
        "-3.2");
    try_joint(
        JointType::SwingTwist, [](JointDesc& d) { d.swing_twist.twist_max = 3.2; }, false, "swing_twist.twist_max",
        "3.2");
    try_joint(
        JointType::SwingTwist,
        [](JointDesc& d) {
            d.swing_twist.twist_min = 0.2;
            d.swing_twist.twist_max = 0.1;
        },
        false, "swing_twist.twist_min", "above twist_max");
}

TEST(InvalidJoint, HingeMotorSetterChecksSpeedAndTorque) {
    for (const Trial& t : kTrials) {
        for (const bool speed : {true, false}) {
            Scene scene = make_scene();
            Scene twin = make_scene();
            const JointHandle hinge = scene.space->create_joint(joint_of(JointType::Hinge, scene));
            twin.space->create_joint(joint_of(JointType::Hinge, twin));
            auto change = [&] {
                if (speed) {
                    scene.space->set_hinge_motor(hinge, true, t.value, 1);
                } else {
                    scene.space->set_hinge_motor(hinge, true, 1, t.value);
                }
            };
            const Rule rule = speed ? Rule::Finite : Rule::NonNegative;
            const char* field = speed ? "speed" : "max_torque";
            if (accepts(rule, t.value)) {
                expect_accepted(change, field, t.name);
            } else {
                expect_rejected(*scene.space, *twin.space, change, field, t.name);
            }
        }
    }
}
