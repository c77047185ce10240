// [[ragdoll]]: the humanoid the entry makes (parts, joints, mass, limits, groups), the
// entry's checks, and ragdolls dropped on a heightfield settling inside their limits.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "scene_test_util.hpp"

namespace spindle {
namespace {

// The parts in the order the entry makes them (docs/scenes.md).
enum Part : std::uint32_t {
    Pelvis,
    Abdomen,
    Chest,
    Head,
    LeftUpperArm,
    LeftForearm,
    RightUpperArm,
    RightForearm,
    LeftThigh,
    LeftShank,
    RightThigh,
    RightShank,
    kParts
};
constexpr std::size_t kJoints = 11;
constexpr Real kDegree = kPi / 180;

// The index of the scene joint between bodies a and b.
std::size_t joint_between(const SceneDesc& scene, std::uint32_t a, std::uint32_t b) {
    for (std::size_t j = 0; j < scene.joints.size(); ++j) {
        if (scene.joints[j].body_a == a && scene.joints[j].body_b == b) return j;
    }
    ADD_FAILURE() << "no joint between bodies " << a << " and " << b;
    return 0;
}

Real capsule_volume(Real half_height, Real radius) {
    return kPi * radius * radius * (2 * half_height + 4 * radius / 3);
}

TEST(SceneRagdoll, OneRagdoll_HasTwelvePartsElevenJointsAndAHumansMass) {
    const SceneDesc scene = parse_scene("[[ragdoll]]\nposition = [1, 2, 3]\n", "one.toml");
    ASSERT_EQ(scene.bodies.size(), std::size_t{kParts});
    ASSERT_EQ(scene.joints.size(), kJoints);
    int hinges = 0, swing_twists = 0;
    for (const SceneJoint& joint : scene.joints) {
        EXPECT_LT(joint.body_a, std::uint32_t{kParts});
        EXPECT_LT(joint.body_b, std::uint32_t{kParts});
        EXPECT_FALSE(joint.desc.collide_connected);
        if (joint.desc.type == JointType::Hinge) {
            ++hinges;
            EXPECT_TRUE(joint.desc.hinge.enable_limit);
        }
        if (joint.desc.type == JointType::SwingTwist) ++swing_twists;
    }
    EXPECT_EQ(hinges, 4);  // elbows and knees
    EXPECT_EQ(swing_twists, 7);
    // The limits table of docs/scenes.md, in degrees: cone and twist, or the hinge's range.
    struct Row {
        Part parent, child;
        JointType type;
        Real cone_or_lower, twist_or_upper, friction;
    };
    const Row table[] = {
        {Pelvis, Abdomen, JointType::SwingTwist, 30, 25, 5},
        {Abdomen, Chest, JointType::SwingTwist, 36, 24, 5},
        {Chest, Head, JointType::SwingTwist, 45, 29, 5},
        {Chest, LeftUpperArm, JointType::SwingTwist, 64, 79, 2.5},
        {Chest, RightUpperArm, JointType::SwingTwist, 64, 79, 2.5},
        {LeftUpperArm, LeftForearm, JointType::Hinge, -5, 150, 2.5},
        {RightUpperArm, RightForearm, JointType::Hinge, -5, 150, 2.5},
        {Pelvis, LeftThigh, JointType::SwingTwist, 45, 33, 5},
        {Pelvis, RightThigh, JointType::SwingTwist, 45, 33, 5},
        {LeftThigh, LeftShank, JointType::Hinge, -5, 135, 5},
        {RightThigh, RightShank, JointType::Hinge, -5, 135, 5},
    };
    for (const Row& row : table) {
        const JointDesc& d = scene.joints[joint_between(scene, row.parent, row.child)].desc;
        SCOPED_TRACE(std::to_string(row.parent) + " -> " + std::to_string(row.child));
        ASSERT_EQ(d.type, row.type);
        if (row.type == JointType::Hinge) {
            EXPECT_NEAR(d.hinge.lower_angle, row.cone_or_lower * kDegree, 1e-12);
            EXPECT_NEAR(d.hinge.upper_angle, row.twist_or_upper * kDegree, 1e-12);
            EXPECT_TRUE(d.hinge.enable_motor);  // friction: a motor held at speed 0
            EXPECT_EQ(d.hinge.motor_speed, 0);
            EXPECT_EQ(d.hinge.max_motor_torque, row.friction);
        } else {
            EXPECT_NEAR(d.swing_twist.cone_half_angle, row.cone_or_lower * kDegree, 1e-12);
            EXPECT_NEAR(d.swing_twist.twist_min, -row.twist_or_upper * kDegree, 1e-12);
            EXPECT_NEAR(d.swing_twist.twist_max, row.twist_or_upper * kDegree, 1e-12);
            EXPECT_EQ(d.swing_twist.max_friction_torque, row.friction);
        }
    }
    // Swing-twist axes point from the parent into the child: up the spine, down the limbs.
    EXPECT_NEAR(scene.joints[joint_between(scene, Chest, Head)].desc.swing_twist.twist_axis_a.y(), 1, 1e-12);
    EXPECT_NEAR(scene.joints[joint_between(scene, Pelvis, LeftThigh)].desc.swing_twist.twist_axis_a.y(), -1, 1e-12);
    const Vec3 arm = scene.joints[joint_between(scene, Chest, LeftUpperArm)].desc.swing_twist.twist_axis_a;
    EXPECT_NEAR(arm.x(), std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(arm.y(), -std::sqrt(0.5), 1e-12);
    // Every part but the pelvis hangs from exactly one joint: a tree.
    std::set<std::uint32_t> children;
    for (const SceneJoint& joint : scene.joints) children.insert(joint.body_b);
    EXPECT_EQ(children.size(), kJoints);
    EXPECT_EQ(children.count(Pelvis), 0u);

    // The layout's volumes (scene_ragdoll.cpp), at the default density of 1000 kg/m^3.
    const Real volume = 0.3 * 0.2 * 0.2                                                   // pelvis box
                        + capsule_volume(0.05, 0.1)                                       // abdomen
                        + 0.34 * 0.28 * 0.2                                               // chest box
                        + capsule_volume(0.03, 0.09)                                      // head
                        + 2 * (capsule_volume(0.15, 0.05) + capsule_volume(0.13, 0.04))   // arms
                        + 2 * (capsule_volume(0.22, 0.07) + capsule_volume(0.21, 0.05));  // legs
    Real mass = 0;
    for (const SceneBody& b : scene.bodies) {
        EXPECT_EQ(b.desc.type, MotionType::Dynamic);
        mass += scene.shapes[b.shape].make().mass_properties(b.desc.density).mass;
    }
    EXPECT_NEAR(mass, 1000 * volume, 1e-9);
    EXPECT_NEAR(mass, 75.9, 0.1);  // an adult's

    // Standing at `position`: the pelvis there, the head above it, the feet 0.97 m below.
    EXPECT_EQ(scene.bodies[Pelvis].desc.position, Vec3(1, 2, 3));
    EXPECT_GT(scene.bodies[Head].desc.position.y(), 2.6);
    EXPECT_NEAR(scene.bodies[LeftShank].desc.position.y(), 2 - 0.71, 1e-12);
    EXPECT_GT(scene.bodies[LeftThigh].desc.position.x(), 1);  // the left side is +x

    Space space;
    build(scene, space);
    EXPECT_EQ(space.body_count(), std::size_t{kParts});
    EXPECT_EQ(space.joint_count(), kJoints);
}

TEST(SceneRagdoll, Mass_IsTheWholeRagdollsSharedByVolume) {
    const SceneDesc scene = parse_scene("[[ragdoll]]\nmass = 80\n", "heavy.toml");
    Real mass = 0;
    for (const SceneBody& b : scene.bodies) mass += b.desc.mass;
    EXPECT_NEAR(mass, 80, 1e-9);
    // The chest box is the biggest part, 0.01904 m^3 of the 0.07593.
    EXPECT_NEAR(scene.bodies[Chest].desc.mass, 80 * 0.01904 / 0.0759253, 0.01);
}

TEST(SceneRagdoll, Orientation_TurnsTheWholeRagdollAboutItsPosition) {
    // A quarter turn about x: lying on its back, head toward -z.
    const SceneDesc scene =
        parse_scene("[[ragdoll]]\nposition = [0, 1, 0]\norientation = { axis = [1, 0, 0], degrees = -90 }\n"
                    "velocity = [1, 0, 0]\nangular_velocity = [0, 2, 0]\n",
                    "lying.toml");
    const Vec3 pelvis = scene.bodies[Pelvis].desc.position;
    EXPECT_NEAR(pelvis.y(), 1, 1e-12);
    const Vec3 head = scene.bodies[Head].desc.position - pelvis;
    EXPECT_NEAR(head.y(), 0, 1e-12);
    EXPECT_NEAR(head.z(), -0.72, 1e-12);
    EXPECT_NEAR(scene.bodies[LeftShank].desc.position.z() - pelvis.z(), 0.71, 1e-12);
    // Moving as one rigid body: each part's velocity is v + w x r.
    for (const SceneBody& b : scene.bodies) {
        const Vec3 expected = Vec3(1, 0, 0) + Vec3(0, 2, 0).cross(b.desc.position - pelvis);
        EXPECT_LE((b.desc.linear_velocity - expected).norm(), 1e-12);
        EXPECT_EQ(b.desc.angular_velocity, Vec3(0, 2, 0));
    }
}

TEST(SceneRagdoll, Groups_OnePerRagdollThatNoOtherBodyUses) {
    // A body written after the ragdolls takes the top group: theirs must step around it.
    const SceneDesc scene = parse_scene("[[body]]\nshape = { sphere = 1 }\ngroup = 7\n"
                                        "[[ragdoll]]\ncopies = { count = [3, 1, 1], step = [3, 0, 0] }\n"
                                        "[[body]]\nshape = { sphere = 1 }\ngroup = 4294967295\n",
                                        "groups.toml");
    ASSERT_EQ(scene.bodies.size(), 2 + 3 * std::size_t{kParts});
    std::set<std::uint32_t> groups;
    for (std::size_t r = 0; r < 3; ++r) {
        const std::uint32_t group = scene.bodies[1 + r * kParts].desc.group;
        EXPECT_NE(group, 0u);
        EXPECT_NE(group, 7u);
        EXPECT_NE(group, 4294967295u);
        for (std::size_t p = 0; p < kParts; ++p) EXPECT_EQ(scene.bodies[1 + r * kParts + p].desc.group, group);
        groups.insert(group);
    }
    EXPECT_EQ(groups.size(), 3u);
    EXPECT_EQ(*groups.rbegin(), 4294967294u);
    EXPECT_EQ(scene.bodies.front().desc.group, 7u);
    EXPECT_EQ(scene.bodies.back().desc.group, 4294967295u);
}

TEST(SceneRagdoll, BrokenRagdolls_AreRejectedAtTheLine) {
    EXPECT_REJECTED("[[ragdoll]]\ntype = \"static\"\n", "2:8", "ragdoll.type: a ragdoll's parts must be dynamic");
    EXPECT_REJECTED("[defaults]\ntype = \"kinematic\"\n[[ragdoll]]\n", "3:1",
                    "ragdoll.type: a ragdoll's parts must be dynamic");
    EXPECT_REJECTED("[[ragdoll]]\nshape = { sphere = 1 }\n", "2:9", "ragdoll.shape: a ragdoll makes its own shapes");
    EXPECT_REJECTED("[[ragdoll]]\ngroup = 3\n", "2:9", "ragdoll.group: every ragdoll gets a collision group");
    EXPECT_REJECTED("[[ragdoll]]\nposition = [0, \"up\", 0]\n", "2:16", "ragdoll.position");
    EXPECT_REJECTED("[[ragdoll]]\ndensity = -5\n", "2:11", "ragdoll.density");
    EXPECT_REJECTED("[[ragdoll]]\nmass = nan\n", "2:8", "ragdoll.mass");
    EXPECT_REJECTED("[[ragdoll]]\ncopies = { count = [2, 0, 1], step = [1, 0, 0] }\n", "2:24", "ragdoll.copies.count");
    EXPECT_REJECTED("[[ragdoll]]\ncopies = { count = [1000, 1000, 1], step = [1, 0, 0] }\n", "1:1",
                    "ragdoll: makes 1.2e+07 bodies; a scene may have at most 2000000");
    EXPECT_REJECTED("[[ragdoll]]\nlinks = 3\n", "2:1", "unknown key 'links' in [[ragdoll]]");
}

// Bends a part about the joint at `pivot` so that its direction `from` turns toward `to`
// by `degrees`, and returns the joint's hinge angle then.
Real hinge_angle_after_bending(Space& space, const std::vector<BodyHandle>& bodies,
                               const std::vector<JointHandle>& joints, std::size_t joint, Part part, const Vec3& pivot,
                               const Vec3& from, const Vec3& to, Real degrees) {
    const Vec3 bent = std::cos(degrees * kDegree) * from + std::sin(degrees * kDegree) * to;
    const Quat turn = Quat::FromTwoVectors(from, bent);
    MotionState state = space.internal_motion_state(bodies[part]);
    state.position = pivot + turn * (state.position - pivot);
    state.center_of_mass = state.position;
    state.orientation = turn * state.orientation;
    space.set_internal_motion_state(bodies[part], state);
    return space.internal_hinge_angle(joints[joint]);
}

TEST(SceneRagdoll, KneesAndElbows_BendTheRightWayWithinTheirLimits) {
    const SceneDesc scene = parse_scene("[settings]\ngravity = [0, 0, 0]\n[[ragdoll]]\n", "bend.toml");
    Space space;
    std::vector<JointHandle> joints;
    const std::vector<BodyHandle> bodies = build(scene, space, &joints);
    ASSERT_EQ(joints.size(), kJoints);
    const Vec3 down(0, -1, 0), forward(0, 0, 1);
    // The knee bends the shank back (-z).
    const std::size_t knee = joint_between(scene, LeftThigh, LeftShank);
    const Vec3 knee_at(0.09, -0.5, 0);
    EXPECT_NEAR(hinge_angle_after_bending(space, bodies, joints, knee, LeftShank, knee_at, down, -forward, 30),
                30 * kDegree, 1e-9);
    EXPECT_NEAR(space.joint_desc(joints[knee]).hinge.upper_angle, 135 * kDegree, 1e-12);
    EXPECT_NEAR(space.joint_desc(joints[knee]).hinge.lower_angle, -5 * kDegree, 1e-12);
    // The elbow bends the forearm forward (+z), on both sides.
    for (const auto& [upper, fore, side] :
         {std::tuple{LeftUpperArm, LeftForearm, 1.0}, std::tuple{RightUpperArm, RightForearm, -1.0}}) {
        const std::size_t elbow = joint_between(scene, upper, fore);
        const Vec3 arm = Vec3(side, -1, 0).normalized();
        const Vec3 elbow_at = Vec3(side * 0.22, 0.54, 0) + 0.3 * arm;
        EXPECT_NEAR(hinge_angle_after_bending(space, bodies, joints, elbow, fore, elbow_at, arm, forward, 40),
                    40 * kDegree, 1e-9)
            << (side > 0 ? "left" : "right") << " elbow";
        EXPECT_NEAR(space.joint_desc(joints[elbow]).hinge.upper_angle, 150 * kDegree, 1e-12);
    }
}

TEST(SceneRagdoll, OwnPartsNeverCollide_OtherRagdollsDo) {
    // Two ragdolls floating side by side, reporting contacts. The first one's left forearm
    // is put inside its own right thigh, the second one's inside the first one's left thigh.
    const SceneDesc scene = parse_scene("[settings]\ngravity = [0, 0, 0]\n"
                                        "[[ragdoll]]\ncontact_events = true\n"
                                        "copies = { count = [2, 1, 1], step = [3, 0, 0] }\n",
                                        "touch.toml");
    Space space;
    const std::vector<BodyHandle> bodies = build(scene, space);
    const BodyHandle own_forearm = bodies[LeftForearm], other_forearm = bodies[kParts + LeftForearm];
    space.set_position(own_forearm, space.position(bodies[RightThigh]) + Vec3(0, 0, 0.05));
    space.set_orientation(own_forearm, space.orientation(bodies[RightThigh]));
    space.set_position(other_forearm, space.position(bodies[LeftThigh]) + Vec3(0, 0, 0.05));
    space.set_orientation(other_forearm, space.orientation(bodies[LeftThigh]));
    std::vector<ContactEvent> events;
    for (int i = 0; i < 3; ++i) {
        space.update();
        space.read_contact_events(events);
    }
    auto in_second = [&](BodyHandle h) {
        return std::find(bodies.begin(), bodies.end(), h) - bodies.begin() >= static_cast<std::ptrdiff_t>(kParts);
    };
    int between = 0;
    for (const ContactEvent& e : events) {
        EXPECT_NE(in_second(e.body_a), in_second(e.body_b))
            << "a contact within one ragdoll: bodies " << e.body_a.index << " and " << e.body_b.index;
        if (in_second(e.body_a) != in_second(e.body_b)) ++between;
    }
    EXPECT_GT(between, 0) << "the second ragdoll's forearm inside the first one's thigh made no contact";
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

// Two piles of two ragdolls on crests and two in troughs of a sine heightfield, as in the
// built-in `ragdolls` scene (the same body properties), small enough for a test. Sleeping
// is off, so that coming to rest is the ragdolls' own doing.
constexpr const char* kPiles = R"(
[settings]
sleep = false
[defaults]
friction = 1
restitution = 0.15
linear_damping = 0.05
angular_damping = 0.05

[[body]]
type = "static"
shape = { heightfield = { size = [12, 12], cells = [12, 12], amplitude = 0.5, wavelength = 8 } }

[[ragdoll]]
position = [-2, 1.1, -2]
orientation = [0.707107, -0.707107, 0, 0]
copies = { count = [2, 1, 2], step = [4, 0, 4] }

[[ragdoll]]
position = [-2, 1.7, -2]
orientation = [0.256238, -0.256238, 0.659046, 0.659046]
copies = { count = [2, 1, 2], step = [4, 0, 4] }
)";

// The terrain's surface below p: a ray down onto it alone.
Real terrain_below(const Space& space, BodyHandle terrain, const Vec3& p) {
    QueryFilter only_terrain;
    only_terrain.accept = [terrain](BodyHandle b) { return b == terrain; };
    const std::optional<QueryHit> hit = space.cast_ray(Vec3(p.x(), 10, p.z()), Vec3(p.x(), -10, p.z()), only_terrain);
    EXPECT_TRUE(hit.has_value()) << "no terrain below " << p.transpose();
    return hit ? hit->point.y() : -kHuge;
}

TEST(SceneRagdoll, PilesOnAHeightfield_SettleInsideTheirLimits) {
    const SceneDesc scene = parse_scene(kPiles, "piles.toml");
    Space space;
    std::vector<JointHandle> joints;
    const std::vector<BodyHandle> bodies = build(scene, space, &joints);
    ASSERT_EQ(bodies.size(), 1 + 8 * std::size_t{kParts});
    constexpr int kSteps = 4 * 60;  // four seconds
    for (int i = 0; i < kSteps; ++i) space.update();

    Real fastest = 0, spinning = 0, lowest = kHuge;
    for (std::size_t i = 1; i < bodies.size(); ++i) {
        const MotionState s = space.internal_motion_state(bodies[i]);
        ASSERT_TRUE(s.position.allFinite() && s.orientation.coeffs().allFinite()) << "body " << i;
        ASSERT_TRUE(s.linear_velocity.allFinite() && s.angular_velocity.allFinite()) << "body " << i;
        fastest = std::max(fastest, s.linear_velocity.norm());
        spinning = std::max(spinning, s.angular_velocity.norm());
        lowest = std::min(lowest, s.position.y() - terrain_below(space, bodies[0], s.position));
    }
    Real worst_linear = 0, worst_angular = 0, worst_hinge = 0;
    for (std::size_t j = 0; j < joints.size(); ++j) {
        const JointError error = space.internal_joint_error(joints[j]);
        worst_linear = std::max(worst_linear, error.linear);
        const JointDesc desc = space.joint_desc(joints[j]);
        if (desc.type == JointType::Hinge) {
            const Real angle = space.internal_hinge_angle(joints[j]);
            worst_hinge = std::max({worst_hinge, desc.hinge.lower_angle - angle, angle - desc.hinge.upper_angle});
            worst_angular = std::max(worst_angular, error.angular);  // the axes' misalignment
        } else if (desc.type == JointType::SwingTwist) {
            worst_angular = std::max(worst_angular, error.angular);  // outside the cone or twist range
        }
    }
    std::printf("ragdoll piles after %d steps: fastest %.2e m/s, %.2e rad/s; lowest centre %.4f m above the "
                "terrain; worst joint error %.5f m, %.5f rad; worst hinge limit violation %.5f rad\n",
                kSteps, fastest, spinning, lowest, worst_linear, worst_angular, worst_hinge);
    // At rest as the engine's sleep test has it (its default thresholds).
    EXPECT_LT(fastest, 0.05);
    EXPECT_LT(spinning, 0.05);
    // No part through the terrain: a centre above the surface (the thinnest part's radius
    // is 4 cm; a part that fell through ends below it).
    EXPECT_GT(lowest, 0);
    // Soft joints stretch a little under load (joint_hertz 60, damping ratio 2): a few
    // times the worst measured (printed above; the commit that set these says what it was)
    // allows for other builds' rounding, and still fails a joint that lets go or a limit
    // that is not held.
    EXPECT_LT(worst_linear, 0.005);
    EXPECT_LT(worst_angular, 1 * kDegree);
    EXPECT_LT(worst_hinge, 1 * kDegree);
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

// One ragdoll dropped on its back across a static bench under its pelvis and abdomen:
// the legs hang off one end, the chest, head and arms off the other, each pulling its
// swing-twist joint against its cone (a leg hanging down is 90 degrees from its rest
// direction, twice the hip's cone). The piles above lie in the middle of their cones and
// hardly load them; a ragdoll without its cone rows settles there just as well.
constexpr const char* kBench = R"(
[settings]
sleep = false
[defaults]
friction = 1
linear_damping = 0.05
angular_damping = 0.05

[[body]]
type = "static"
shape = { plane = { normal = [0, 1, 0] } }

[[body]]
type = "static"
shape = { box = [0.5, 0.05, 0.185] }
position = [0, 1.04, -0.165]

[[ragdoll]]
position = [0, 1.2, 0]
orientation = [0.707107, -0.707107, 0, 0]
)";
constexpr Real kBenchTop = 1.09;

TEST(SceneRagdoll, OnABench_LimbsHangingOffBothEndsStayInTheirCones) {
    const SceneDesc scene = parse_scene(kBench, "bench.toml");
    Space space;
    std::vector<JointHandle> joints;
    const std::vector<BodyHandle> bodies = build(scene, space, &joints);
    ASSERT_EQ(joints.size(), kJoints);
    constexpr int kSteps = 4 * 60;
    for (int i = 0; i < kSteps; ++i) space.update();

    const std::vector<BodyHandle> parts(bodies.begin() + 2, bodies.end());
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const MotionState s = space.internal_motion_state(parts[i]);
        ASSERT_TRUE(s.position.allFinite() && s.orientation.coeffs().allFinite()) << "part " << i;
    }
    // Still lying on the bench (not slid off to the floor, where nothing hangs), the
    // feet well below it.
    EXPECT_GT(space.internal_position(parts[Pelvis]).y(), kBenchTop);
    EXPECT_LT(space.internal_position(parts[LeftShank]).y(), kBenchTop - 0.3);
    EXPECT_LT(space.internal_position(parts[RightShank]).y(), kBenchTop - 0.3);
    Real worst_swing_twist = 0, worst_linear = 0;
    for (JointHandle joint : joints) {
        const JointError error = space.internal_joint_error(joint);
        worst_linear = std::max(worst_linear, error.linear);
        if (space.joint_desc(joint).type == JointType::SwingTwist)
            worst_swing_twist = std::max(worst_swing_twist, error.angular);
    }
    std::printf("ragdoll on a bench after %d steps: worst swing-twist violation %.5f rad, anchors %.5f m apart\n",
                kSteps, worst_swing_twist, worst_linear);
    // The soft joints hold the hanging limbs a little past their cones; a few times the
    // worst measured (printed above) still fails a cone that is not held.
    EXPECT_LT(worst_swing_twist, 2 * kDegree);
    EXPECT_LT(worst_linear, 0.015);
}

}  // namespace
}  // namespace spindle
