// [[ragdoll]]: a humanoid of boxes and capsules on swing-twist joints and limited hinges
// (the layout and the table of joint limits below), each copy in a collision group of its
// own, so that its parts never collide with each other but do with everything else.
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "scene_parts.hpp"

namespace spindle::scene_detail {
namespace {

constexpr Real kDegree = kPi / 180;

// The parts, in the order their bodies are made.
enum Part : std::uint8_t {
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
    kPartCount
};

enum class Kind : std::uint8_t { SwingTwist, Hinge };

// Joint limits, in degrees. A swing-twist joint lets the child swing up to `cone` from
// its rest direction (the twist axis) and twist about it within [-twist, twist]; a hinge
// bends within [lower, upper], 0 straight, positive bending the elbow forward and the
// knee back.
//
//   joint       parent     child      kind         twist axis at rest   cone  twist   hinge    friction
//   lower back  pelvis     abdomen    swing-twist  up the spine          30   ±25              5 N m
//   upper back  abdomen    chest      swing-twist  up the spine          36   ±24              5
//   neck        chest      head       swing-twist  up the spine          45   ±29              5
//   shoulder    chest      upper arm  swing-twist  down the arm          64   ±79              2.5
//   elbow       upper arm  forearm    hinge                                          -5..150   2.5
//   hip         pelvis     thigh      swing-twist  down the leg          45   ±33              5
//   knee        thigh      shank      hinge                                          -5..135   5
//
// The swing-twist rows are Jolt's ragdoll (JoltPhysics Assets/Human.tof, the humanoid of
// its PerformanceTest "Ragdoll" scene). Jolt's cones are elliptical; these are round, with
// Jolt's larger half-angle (its "normal" one), and where one joint here stands for several
// of Jolt's (its spine has four joints, its neck and head four, its shoulder a clavicle
// joint too) the largest of them: lower back C_Spine_0; upper back C_Spine_1 (cone) and
// C_Spine_4 (twist); neck C_Head_0 (cone) and C_Neck_1 (twist); shoulder L_Arm_0; hip
// L_Leg_0. The hinge rows are common clinical ranges of motion (elbow flexion to 150
// degrees, knee to 135) with 5 degrees of hyperextension; Jolt makes elbows and knees
// narrow swing-twist joints instead. Friction is Human.tof's joint friction; a hinge's is
// its motor held at speed 0. Each joint's rest pose (the one built) is the middle of its
// cone, so arms hang 45 degrees out from the body.
struct Limits {
    Kind kind;
    Real cone, twist;   // swing-twist
    Real lower, upper;  // hinge
    Real friction;      // N m
};
constexpr Limits kLowerBack{Kind::SwingTwist, 30, 25, 0, 0, 5};
constexpr Limits kUpperBack{Kind::SwingTwist, 36, 24, 0, 0, 5};
constexpr Limits kNeck{Kind::SwingTwist, 45, 29, 0, 0, 5};
constexpr Limits kShoulder{Kind::SwingTwist, 64, 79, 0, 0, 2.5};
constexpr Limits kElbow{Kind::Hinge, 0, 0, -5, 150, 2.5};
constexpr Limits kHip{Kind::SwingTwist, 45, 33, 0, 0, 5};
constexpr Limits kKnee{Kind::Hinge, 0, 0, -5, 135, 5};

// A part's shape in the standing pose: a box about `centre`, or a capsule whose segment
// runs from `from` to `to` (its end spheres centred on the joints, so neighbours overlap
// there; they never collide).
struct PartLayout {
    ShapeType type;
    Vec3 centre, half_extents;  // box
    Vec3 from, to;              // capsule
    Real radius;                // capsule
};

struct JointLayout {
    Part parent, child;
    Vec3 anchor;
    Vec3 axis;  // swing-twist: the twist axis (the child's direction); hinge: the hinge axis
    Limits limits;
};

struct Humanoid {
    std::array<PartLayout, kPartCount> parts;
    std::array<JointLayout, kPartCount - 1> joints;  // a tree: one joint per part but the pelvis
};

PartLayout box(const Vec3& centre, const Vec3& half_extents) {
    return {ShapeType::Box, centre, half_extents, Vec3::Zero(), Vec3::Zero(), 0};
}

PartLayout capsule(const Vec3& from, const Vec3& to, Real radius) {
    return {ShapeType::Capsule, (from + to) / 2, Vec3::Zero(), from, to, radius};
}

// Standing, the pelvis centre at the origin, facing +z, the left side at +x; metres.
// A 1.8 m adult: thigh 0.44 m, shank 0.42 (the capsule's end is the foot), upper arm
// 0.30, forearm 0.26 (its end is the hand); about 76 kg at the default density.
Humanoid make_humanoid() {
    const Vec3 up = Vec3::UnitY(), down = -Vec3::UnitY(), forward = Vec3::UnitZ();
    Humanoid h;
    h.parts[Pelvis] = box(Vec3(0, 0, 0), Vec3(0.15, 0.1, 0.1));
    h.parts[Abdomen] = capsule(Vec3(-0.05, 0.2, 0), Vec3(0.05, 0.2, 0), 0.1);
    h.parts[Chest] = box(Vec3(0, 0.44, 0), Vec3(0.17, 0.14, 0.1));
    h.parts[Head] = capsule(Vec3(0, 0.69, 0), Vec3(0, 0.75, 0), 0.09);
    h.joints[0] = {Pelvis, Abdomen, Vec3(0, 0.1, 0), up, kLowerBack};
    h.joints[1] = {Abdomen, Chest, Vec3(0, 0.3, 0), up, kUpperBack};
    h.joints[2] = {Chest, Head, Vec3(0, 0.6, 0), up, kNeck};
    std::size_t joint = 3;
    for (const Real side : {1.0, -1.0}) {  // left, then right
        const bool left = side > 0;
        const Vec3 arm = Vec3(side, -1, 0).normalized();
        const Vec3 shoulder(side * 0.22, 0.54, 0);
        const Vec3 elbow = shoulder + 0.30 * arm;
        const Vec3 wrist = elbow + 0.26 * arm;
        const Part upper_arm = left ? LeftUpperArm : RightUpperArm, forearm = left ? LeftForearm : RightForearm;
        h.parts[upper_arm] = capsule(shoulder, elbow, 0.05);
        h.parts[forearm] = capsule(elbow, wrist, 0.04);
        h.joints[joint++] = {Chest, upper_arm, shoulder, arm, kShoulder};
        // The hinge angle grows as the forearm turns about this axis: toward `forward`.
        h.joints[joint++] = {upper_arm, forearm, elbow, arm.cross(forward).normalized(), kElbow};

        const Vec3 hip(side * 0.09, -0.06, 0);
        const Vec3 knee = hip + 0.44 * down;
        const Vec3 ankle = knee + 0.42 * down;
        const Part thigh = left ? LeftThigh : RightThigh, shank = left ? LeftShank : RightShank;
        h.parts[thigh] = capsule(hip, knee, 0.07);
        h.parts[shank] = capsule(knee, ankle, 0.05);
        h.joints[joint++] = {Pelvis, thigh, hip, down, kHip};
        // Toward -forward: the knee bends back.
        h.joints[joint++] = {thigh, shank, knee, forward.cross(down), kKnee};
    }
    return h;
}

const Humanoid& humanoid() {
    static const Humanoid h = make_humanoid();
    return h;
}

ShapeSpec part_shape(const PartLayout& part) {
    ShapeSpec s;
    s.type = part.type;
    if (part.type == ShapeType::Box) {
        s.half_extents = part.half_extents;
    } else {
        s.radius = part.radius;
        s.half_height = (part.to - part.from).norm() / 2;
    }
    return s;
}

// Capsules are built along y; turn each onto its segment (pointing it up, so that a
// vertical one keeps the identity instead of a half turn about an arbitrary axis).
Quat part_orientation(const PartLayout& part) {
    if (part.type == ShapeType::Box) return Quat::Identity();
    const Vec3 along = part.to - part.from;
    return Quat::FromTwoVectors(Vec3::UnitY(), along.y() < 0 ? Vec3(-along) : along);
}

Real part_volume(const ShapeSpec& s) {
    if (s.type == ShapeType::Box) return 8 * s.half_extents.prod();
    return kPi * s.radius * s.radius * (2 * s.half_height + 4 * s.radius / 3);
}

JointDesc part_joint(const JointLayout& joint, const Vec3& anchor, const Vec3& axis) {
    if (joint.limits.kind == Kind::Hinge) {
        JointDesc d = JointDesc::hinge_at({}, {}, anchor, axis);
        d.hinge.enable_limit = true;
        d.hinge.lower_angle = joint.limits.lower * kDegree;
        d.hinge.upper_angle = joint.limits.upper * kDegree;
        d.hinge.enable_motor = true;
        d.hinge.motor_speed = 0;
        d.hinge.max_motor_torque = joint.limits.friction;
        return d;
    }
    JointDesc d = JointDesc::swing_twist_at({}, {}, anchor, axis);
    d.swing_twist.cone_half_angle = joint.limits.cone * kDegree;
    d.swing_twist.twist_min = -joint.limits.twist * kDegree;
    d.swing_twist.twist_max = joint.limits.twist * kDegree;
    d.swing_twist.max_friction_torque = joint.limits.friction;
    return d;
}

}  // namespace

void parse_ragdoll(const TomlReader& r, const toml::table& entry, const BodyTemplate& defaults, SceneDesc& scene,
                   std::vector<RagdollBodies>& ragdolls) {
    const std::string where = "ragdoll";
    std::vector<std::string_view> allowed = body_property_keys();
    allowed.push_back("position");
    allowed.push_back("copies");
    r.check_keys(entry, "[[" + where + "]]", allowed);

    BodyTemplate body = defaults;
    for (auto&& [key, value] : entry) {
        if (key.str() == "shape") r.fail(value, where + ".shape: a ragdoll makes its own shapes; remove the key");
        if (key.str() == "group") {
            r.fail(value, where + ".group: every ragdoll gets a collision group of its own; remove the key");
        }
        apply_body_key(r, key.str(), value, where, body, scene);
    }
    if (body.desc.type != MotionType::Dynamic) {
        const toml::node* type = entry.get("type");
        r.fail(type ? type->source() : entry.source(), where + ".type: a ragdoll's parts must be dynamic");
    }
    const Vec3 origin = entry.get("position") ? r.vec3(*entry.get("position"), where + ".position", "x, y, z in m")
                                              : Vec3::Zero();
    const Copies copies = entry.get("copies") ? parse_copies(r, *entry.get("copies"), where + ".copies") : Copies{};
    const double total = static_cast<double>(kPartCount) * copies.total();
    if (static_cast<double>(scene.bodies.size()) + total > static_cast<double>(kMaxSceneBodies)) {
        r.fail(entry.source(), where + ": makes " + show(total) + " bodies; a scene may have at most " +
                                   std::to_string(kMaxSceneBodies));
    }

    // The shapes, shared by every copy.
    const Humanoid& h = humanoid();
    std::array<std::uint32_t, kPartCount> shape{};
    std::array<Real, kPartCount> volume{};
    Real total_volume = 0;
    for (std::size_t p = 0; p < kPartCount; ++p) {
        // A right part comes two after its left twin (Part) and shares its shape.
        const bool mirrored = p == RightUpperArm || p == RightForearm || p == RightThigh || p == RightShank;
        const ShapeSpec s = part_shape(h.parts[p]);
        volume[p] = part_volume(s);
        total_volume += volume[p];
        if (mirrored) {
            shape[p] = shape[p - 2];
        } else {
            scene.shapes.push_back(s);
            shape[p] = static_cast<std::uint32_t>(scene.shapes.size() - 1);
        }
    }

    // `orientation` and the velocities apply to the whole ragdoll, turning and moving it
    // as one rigid body about `position`.
    const Quat turn = body.desc.orientation;
    const Vec3 velocity = body.desc.linear_velocity, spin = body.desc.angular_velocity;
    const toml::source_position at = entry.source().begin;
    reserve_bodies(scene, static_cast<std::size_t>(total));
    for (std::int64_t cz = 0; cz < copies.count[2]; ++cz) {
        for (std::int64_t cy = 0; cy < copies.count[1]; ++cy) {
            for (std::int64_t cx = 0; cx < copies.count[0]; ++cx) {
                const Vec3 root = origin + Vec3(copies.step.x() * static_cast<Real>(cx),
                                                copies.step.y() * static_cast<Real>(cy),
                                                copies.step.z() * static_cast<Real>(cz));
                const auto first = static_cast<std::uint32_t>(scene.bodies.size());
                for (std::size_t p = 0; p < kPartCount; ++p) {
                    SceneBody b;
                    b.desc = body.desc;
                    const Vec3 offset = turn * h.parts[p].centre;
                    b.desc.position = root + offset;
                    b.desc.orientation = turn * part_orientation(h.parts[p]);
                    b.desc.linear_velocity = velocity + spin.cross(offset);
                    // A ragdoll's `mass` is the whole ragdoll's, shared by volume.
                    if (body.desc.mass > 0) b.desc.mass = body.desc.mass * volume[p] / total_volume;
                    b.desc.group = 0;  // assign_ragdoll_groups
                    b.shape = shape[p];
                    b.line = at.line;
                    b.column = at.column;
                    scene.bodies.push_back(std::move(b));
                }
                for (const JointLayout& j : h.joints) {
                    SceneJoint joint;
                    joint.desc = part_joint(j, root + turn * j.anchor, turn * j.axis);
                    joint.body_a = first + j.parent;
                    joint.body_b = first + j.child;
                    joint.line = at.line;
                    joint.column = at.column;
                    scene.joints.push_back(joint);
                }
                ragdolls.push_back({first, static_cast<std::uint32_t>(kPartCount)});
            }
        }
    }
}

void assign_ragdoll_groups(const TomlReader& r, SceneDesc& scene, const std::vector<RagdollBodies>& ragdolls) {
    if (ragdolls.empty()) return;
    // The groups other bodies were given (a ragdoll's are still 0 here): no ragdoll may
    // share one, or it would stop colliding with those bodies.
    std::vector<std::uint32_t> taken;
    for (const SceneBody& b : scene.bodies) {
        if (b.desc.group != 0) taken.push_back(b.desc.group);
    }
    std::sort(taken.begin(), taken.end());
    // Counting down from the top keeps clear of the small numbers files write by hand.
    // A scene's at most kMaxSceneBodies bodies leave billions of free groups.
    std::uint32_t next = UINT32_MAX;
    for (const RagdollBodies& ragdoll : ragdolls) {
        while (next != 0 && std::binary_search(taken.begin(), taken.end(), next)) --next;
        if (next == 0) throw Error(std::string(r.source()) + ": no collision group left for a ragdoll");
        for (std::uint32_t i = 0; i < ragdoll.count; ++i) scene.bodies[ragdoll.first + i].desc.group = next;
        --next;
    }
}

}  // namespace spindle::scene_detail
