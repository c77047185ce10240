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
    d.prismatic.axis_a = Vec3(0, 1, 0);
    d.prismatic.enable_limit = true;
    d.prismatic.lower_translation = -0.5;
    d.prismatic.upper_translation = 0.5;
    d.prismatic.enable_spring = true;
    d.prismatic.spring_hertz = 2;
    d.prismatic.spring_damping_ratio = 0.5;
    d.prismatic.target_translation = 0.1;
    d.prismatic.enable_motor = true;
    d.prismatic.motor_speed = 1;
    d.prismatic.max_motor_force = 10;
    d.motor.linear_offset = Vec3(0.1, 0.2, 0.3);
    d.motor.angular_offset = Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ()));
    d.motor.max_force = 10;
    d.motor.max_torque = 5;
    d.motor.linear_hertz = 2;
    d.motor.angular_hertz = 3;
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
        {"hinge.limit_spring_hertz", &HingeParams::limit_spring_hertz, Rule::NonNegative},
        {"hinge.limit_damping_ratio", &HingeParams::limit_damping_ratio, Rule::NonNegative},
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

// With World anchors a hinge's or swing-twist's axis is one world axis, given for each
// body: two different ones (a joint born bent or swung) are rejected, one given at two
// lengths is accepted. In the Local frame each body's axis is its own.
TEST(InvalidJoint, WorldFrameAxesMustBeOneAxis) {
    for (JointType type : {JointType::Hinge, JointType::SwingTwist}) {
        const bool hinge = type == JointType::Hinge;
        const std::string field_b = hinge ? "hinge.axis_b" : "swing_twist.twist_axis_b";
        auto set = [hinge](JointDesc& d, const Vec3& a, const Vec3& b) {
            (hinge ? d.hinge.axis_a : d.swing_twist.twist_axis_a) = a;
            (hinge ? d.hinge.axis_b : d.swing_twist.twist_axis_b) = b;
        };
        try_joint(
            type, [&](JointDesc& d) { set(d, Vec3(0, 1, 0), Vec3(1, 0, 0)); }, false, field_b, "perpendicular");
        try_joint(
            type, [&](JointDesc& d) { set(d, Vec3(0, 1, 0), Vec3(0, -1, 0)); }, false, field_b, "opposite");
        try_joint(
            type, [&](JointDesc& d) { set(d, Vec3(0, 1, 0), Vec3(0, 1, 1e-3)); }, false, field_b, "1 mrad off");
        try_joint(
            type, [&](JointDesc& d) { set(d, Vec3(0, 1, 0), Vec3(0, 3, 0)); }, true, field_b, "longer");
        try_joint(
            type,
            [&](JointDesc& d) {
                d.anchors = JointAnchors::local(Vec3::Zero(), Vec3::Zero());
                set(d, Vec3(0, 1, 0), Vec3(1, 0, 0));
            },
            true, field_b, "local frame");
    }
}

TEST(InvalidJoint, PrismaticFieldsFollowTheirRules) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Prismatic,
                [&](JointDesc& d) {
                    d.prismatic.axis_a = Vec3(1, 1, 1);
                    d.prismatic.axis_a[axis] = t.value;
                },
                accepts(Rule::Finite, t.value), "prismatic.axis_a", t.name);
        }
    }
    try_joint(
        JointType::Prismatic, [](JointDesc& d) { d.prismatic.axis_a = Vec3::Zero(); }, false, "prismatic.axis_a",
        "zero");
    const std::vector<std::tuple<const char*, Real PrismaticParams::*, Rule>> fields{
        {"prismatic.lower_translation", &PrismaticParams::lower_translation, Rule::Finite},       // <= upper (0.5)
        {"prismatic.upper_translation", &PrismaticParams::upper_translation, Rule::NonNegative},  // -1 < lower
        {"prismatic.spring_hertz", &PrismaticParams::spring_hertz, Rule::NonNegative},
        {"prismatic.spring_damping_ratio", &PrismaticParams::spring_damping_ratio, Rule::NonNegative},
        {"prismatic.target_translation", &PrismaticParams::target_translation, Rule::Finite},
        {"prismatic.motor_speed", &PrismaticParams::motor_speed, Rule::Finite},
        {"prismatic.max_motor_force", &PrismaticParams::max_motor_force, Rule::NonNegative},
    };
    for (const auto& [field, member, rule] : fields) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Prismatic, [&](JointDesc& d) { d.prismatic.*member = t.value; }, accepts(rule, t.value),
                field, t.name);
        }
    }
}

TEST(InvalidJoint, MotorFieldsFollowTheirRules) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Motor, [&](JointDesc& d) { d.motor.linear_offset[axis] = t.value; },
                accepts(Rule::Finite, t.value), "motor.linear_offset", t.name);
        }
    }
    try_joint(
        JointType::Motor, [](JointDesc& d) { d.motor.angular_offset = Quat(0, 0, 0, 0); }, false,
        "motor.angular_offset", "zero");
    try_joint(
        JointType::Motor, [](JointDesc& d) { d.motor.angular_offset.x() = kNaN; }, false, "motor.angular_offset",
        "nan");
    const std::vector<std::tuple<const char*, Real MotorParams::*, Rule>> fields{
        {"motor.max_force", &MotorParams::max_force, Rule::NonNegative},
        {"motor.max_torque", &MotorParams::max_torque, Rule::NonNegative},
        {"motor.linear_hertz", &MotorParams::linear_hertz, Rule::NonNegative},
        {"motor.linear_damping_ratio", &MotorParams::linear_damping_ratio, Rule::NonNegative},
        {"motor.angular_hertz", &MotorParams::angular_hertz, Rule::NonNegative},
        {"motor.angular_damping_ratio", &MotorParams::angular_damping_ratio, Rule::NonNegative},
    };
    for (const auto& [field, member, rule] : fields) {
        for (const Trial& t : kTrials) {
            try_joint(
                JointType::Motor, [&](JointDesc& d) { d.motor.*member = t.value; }, accepts(rule, t.value), field,
                t.name);
        }
    }
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

TEST(InvalidJoint, MotorTargetSettersCheckEveryComponent) {
    for (const Trial& t : kTrials) {
        for (int field = 0; field < 3; ++field) {
            for (int axis = 0; axis < 3; ++axis) {
                Scene scene = make_scene();
                Scene twin = make_scene();
                const JointHandle motor = scene.space->create_joint(joint_of(JointType::Motor, scene));
                twin.space->create_joint(joint_of(JointType::Motor, twin));
                Vec3 v(0.1, 0.2, 0.3);
                v[axis] = t.value;
                Quat q = Quat::Identity();
                q.coeffs()[axis] = t.value;
                auto change = [&] {
                    if (field == 0) scene.space->set_motor_target(motor, v, Quat::Identity());
                    if (field == 1) scene.space->set_motor_target(motor, Vec3::Zero(), q);
                    if (field == 2) scene.space->set_mouse_target(motor, v);
                };
                const char* name = field == 0 ? "linear_offset" : field == 1 ? "angular_offset" : "world_target";
                // A quaternion is fine with any finite component but not all zero (w stays 1 here).
                if (std::isfinite(t.value)) {
                    expect_accepted(change, name, t.name);
                } else {
                    expect_rejected(*scene.space, *twin.space, change, name, t.name);
                }
            }
        }
    }
}
