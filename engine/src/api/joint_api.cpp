// Space's joint API: validation, creation (frames from the bodies' poses), destruction,
// and reading a joint's error; plus the broadphase's question whether a joint turns a
// pair's collision off.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <cmath>

#include "api/describe.hpp"
#include "api/validation.hpp"
#include "solver/joint_rows.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/stages.hpp"

namespace spindle {

std::string to_string(JointHandle handle) {
    return "joint " + std::to_string(handle.index) + " (generation " + std::to_string(handle.generation) + ")";
}

const char* to_string(JointType type) noexcept {
    switch (type) {
        case JointType::BallSocket: return "ball-socket";
        case JointType::Hinge: return "hinge";
        case JointType::Fixed: return "fixed";
        case JointType::Distance: return "distance";
        case JointType::Prismatic: return "prismatic";
        case JointType::SwingTwist: return "swing-twist";
        case JointType::Motor: return "motor";
    }
    return "?";
}

JointDesc JointDesc::ball_socket_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor) {
    JointDesc d;
    d.type = JointType::BallSocket;
    d.body_a = a;
    d.body_b = b;
    d.anchors = JointAnchors::world(world_anchor);
    return d;
}

JointDesc JointDesc::hinge_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_axis) {
    JointDesc d = ball_socket_at(a, b, world_anchor);
    d.type = JointType::Hinge;
    d.hinge.axis_a = world_axis;
    d.hinge.axis_b = world_axis;
    return d;
}

JointDesc JointDesc::fixed_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor) {
    JointDesc d = ball_socket_at(a, b, world_anchor);
    d.type = JointType::Fixed;
    return d;
}

JointDesc JointDesc::prismatic_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor, const Vec3& world_axis) {
    JointDesc d = ball_socket_at(a, b, world_anchor);
    d.type = JointType::Prismatic;
    d.prismatic.axis_a = world_axis;
    return d;
}

JointDesc JointDesc::swing_twist_at(BodyHandle a, BodyHandle b, const Vec3& world_anchor,
                                    const Vec3& world_twist_axis) {
    JointDesc d = ball_socket_at(a, b, world_anchor);
    d.type = JointType::SwingTwist;
    d.swing_twist.twist_axis_a = world_twist_axis;
    d.swing_twist.twist_axis_b = world_twist_axis;
    return d;
}

JointDesc JointDesc::motor_between(BodyHandle a, BodyHandle b, const Vec3& world_anchor) {
    JointDesc d = ball_socket_at(a, b, world_anchor);
    d.type = JointType::Motor;
    return d;
}

JointDesc JointDesc::mouse_at(BodyHandle world, BodyHandle body, const Vec3& world_point, Real hertz,
                              Real damping_ratio, Real max_force) {
    JointDesc d = motor_between(world, body, world_point);
    d.motor.max_force = max_force;
    d.motor.linear_hertz = hertz;
    d.motor.linear_damping_ratio = damping_ratio;
    d.collide_connected = true;  // a dragged body still rests on the ground it is dragged over
    return d;
}

JointDesc JointDesc::distance_between(BodyHandle a, BodyHandle b, const Vec3& world_anchor_a,
                                      const Vec3& world_anchor_b) {
    JointDesc d;
    d.type = JointType::Distance;
    d.body_a = a;
    d.body_b = b;
    d.anchors = JointAnchors::world(world_anchor_a, world_anchor_b);
    return d;
}

namespace {

// Throws "create_joint: <field> <rule>, got <value>" unless ok.
void require(bool ok, const char* field, const char* rule, const std::string& got) {
    if (!ok) reject_field("create_joint", field, rule, got);
}

void require_finite(const Vec3& v, const char* field) { check_finite(v, "create_joint", field); }
void require_axis(const Vec3& v, const char* field) { check_direction(v, "create_joint", field); }
void require_non_negative(Real value, const char* field) { check_non_negative(value, "create_joint", field); }

void require_ordered(Real lower, Real upper, const char* lower_field, const char* upper_field) {
    if (!(lower <= upper)) {
        throw Error(std::string("create_joint: ") + lower_field + " (" + number(lower) + ") must be <= " + upper_field +
                    " (" + number(upper) + ")");
    }
}

[[noreturn]] void reject(const std::string& what) { throw Error("create_joint: " + what); }

// Lengths and translations a joint drives its bodies to: at most the world's width (two
// points within kMaxCoordinate of the origin); motor speeds at most kMaxCoordinate (m/s
// or rad/s, far past the solver's speed limits). Beyond those the joint's error or its
// impulses overflow: a 1e300 m rest length made every pose NaN.
constexpr Real kMaxJointLength = 2 * kMaxCoordinate;
void require_within(Real value, Real bound, const char* who, const char* field) {
    if (!(std::isfinite(value) && std::abs(value) <= bound)) {
        reject_field(who, field, ("must be finite and within +-" + number(bound)).c_str(), number(value));
    }
}

// In the World frame both bodies' axes are one world axis (hinge, swing-twist): given
// twice, the two must agree (after normalising). In the Local frame each is its body's.
void require_same_world_axis(const JointDesc& d, const Vec3& a, const Vec3& b, const char* field_a,
                             const char* field_b) {
    constexpr Real kSameAxis = 1e-6;  // between the unit axes
    if (d.anchors.frame != JointFrame::World || (a.normalized() - b.normalized()).norm() <= kSameAxis) return;
    reject(std::string(field_b) + " must be the same world axis as " + field_a + " with World anchors, got " + vec(b) +
           " and " + vec(a));
}

void validate(const World& world, const JointDesc& d) {
    const Bodies& b = world.bodies;
    if (!b.is_live(d.body_a))
        reject("body_a: " + to_string(d.body_a) + " is not a live body (stale or foreign handle)");
    if (!b.is_live(d.body_b))
        reject("body_b: " + to_string(d.body_b) + " is not a live body (stale or foreign handle)");
    if (d.body_a == d.body_b) reject("body_a and body_b must be different bodies, both are " + to_string(d.body_a));
    if (b.type[d.body_a.index] != MotionType::Dynamic && b.type[d.body_b.index] != MotionType::Dynamic) {
        reject("at least one of body_a and body_b must be dynamic");
    }
    if (d.type != JointType::BallSocket && d.type != JointType::Hinge && d.type != JointType::Fixed &&
        d.type != JointType::Distance && d.type != JointType::SwingTwist && d.type != JointType::Prismatic &&
        d.type != JointType::Motor) {
        reject("type is not a joint type (" + std::to_string(static_cast<int>(d.type)) + ")");
    }
    if (d.anchors.frame != JointFrame::World && d.anchors.frame != JointFrame::Local) {
        reject("anchors.frame is neither World nor Local");
    }
    // Anchors are points (in world, or in a body's frame): held to the positions' bound,
    // which keeps the lever arms' squares, the effective masses and the joint's error
    // finite. One a light-year off is no anchor a game means; it made every pose NaN.
    check_position(d.anchors.a, "create_joint", "anchors.a");
    check_position(d.anchors.b, "create_joint", "anchors.b");
    if (d.type == JointType::Hinge) {
        const HingeParams& h = d.hinge;
        require_axis(h.axis_a, "hinge.axis_a");
        require_axis(h.axis_b, "hinge.axis_b");
        require_same_world_axis(d, h.axis_a, h.axis_b, "hinge.axis_a", "hinge.axis_b");
        if (h.enable_limit) {
            for (auto [value, field] :
                 {std::pair{h.lower_angle, "hinge.lower_angle"}, {h.upper_angle, "hinge.upper_angle"}}) {
                require(std::isfinite(value) && std::abs(value) <= kPi, field, "must be in [-pi, pi]", number(value));
            }
            require_ordered(h.lower_angle, h.upper_angle, "hinge.lower_angle", "hinge.upper_angle");
        }
        require_non_negative(h.limit_spring_hertz, "hinge.limit_spring_hertz");
        require_non_negative(h.limit_damping_ratio, "hinge.limit_damping_ratio");
        require_within(h.motor_speed, kMaxCoordinate, "create_joint", "hinge.motor_speed");
        require_non_negative(h.max_motor_torque, "hinge.max_motor_torque");
    }
    if (d.type == JointType::SwingTwist) {
        const SwingTwistParams& p = d.swing_twist;
        require_axis(p.twist_axis_a, "swing_twist.twist_axis_a");
        require_axis(p.twist_axis_b, "swing_twist.twist_axis_b");
        require_same_world_axis(d, p.twist_axis_a, p.twist_axis_b, "swing_twist.twist_axis_a",
                                "swing_twist.twist_axis_b");
        require(std::isfinite(p.cone_half_angle) && p.cone_half_angle >= 0 && p.cone_half_angle <= kPi,
                "swing_twist.cone_half_angle", "must be in [0, pi]", number(p.cone_half_angle));
        for (auto [value, field] :
             {std::pair{p.twist_min, "swing_twist.twist_min"}, {p.twist_max, "swing_twist.twist_max"}}) {
            require(std::isfinite(value) && std::abs(value) <= kPi, field, "must be in [-pi, pi]", number(value));
        }
        require_ordered(p.twist_min, p.twist_max, "swing_twist.twist_min", "swing_twist.twist_max");
        require_non_negative(p.max_friction_torque, "swing_twist.max_friction_torque");
    }
    if (d.type == JointType::Prismatic) {
        const PrismaticParams& p = d.prismatic;
        require_axis(p.axis_a, "prismatic.axis_a");
        require_within(p.lower_translation, kMaxJointLength, "create_joint", "prismatic.lower_translation");
        require_within(p.upper_translation, kMaxJointLength, "create_joint", "prismatic.upper_translation");
        if (p.enable_limit) {
            require_ordered(p.lower_translation, p.upper_translation, "prismatic.lower_translation",
                            "prismatic.upper_translation");
        }
        require_non_negative(p.spring_hertz, "prismatic.spring_hertz");
        require_non_negative(p.spring_damping_ratio, "prismatic.spring_damping_ratio");
        require_within(p.target_translation, kMaxJointLength, "create_joint", "prismatic.target_translation");
        require_within(p.motor_speed, kMaxCoordinate, "create_joint", "prismatic.motor_speed");
        require_non_negative(p.max_motor_force, "prismatic.max_motor_force");
    }
    if (d.type == JointType::Motor) {
        const MotorParams& p = d.motor;
        require_finite(p.linear_offset, "motor.linear_offset");
        check_orientation(p.angular_offset, "create_joint", "motor.angular_offset");
        require_non_negative(p.max_force, "motor.max_force");
        require_non_negative(p.max_torque, "motor.max_torque");
        require_non_negative(p.linear_hertz, "motor.linear_hertz");
        require_non_negative(p.linear_damping_ratio, "motor.linear_damping_ratio");
        require_non_negative(p.angular_hertz, "motor.angular_hertz");
        require_non_negative(p.angular_damping_ratio, "motor.angular_damping_ratio");
    }
    if (d.type == JointType::Distance) {
        const DistanceParams& p = d.distance;
        require_within(p.rest_length, kMaxJointLength, "create_joint", "distance.rest_length");
        require_non_negative(p.spring_hertz, "distance.spring_hertz");
        require_non_negative(p.spring_damping_ratio, "distance.spring_damping_ratio");
        require_non_negative(p.min_length, "distance.min_length");
        require_within(p.min_length, kMaxJointLength, "create_joint", "distance.min_length");
        require(std::isfinite(p.max_length), "distance.max_length", "must be finite", number(p.max_length));
        require_ordered(p.min_length, p.max_length, "distance.min_length", "distance.max_length");
    }
}

// The joint's frames in each body's centre-of-mass frame, from the bodies' poses now.
Joint make_joint(const World& world, const JointDesc& d) {
    const Bodies& b = world.bodies;
    const std::uint32_t sa = d.body_a.index, sb = d.body_b.index;
    const Quat qa = b.q[sa], qb = b.q[sb];
    Joint j;
    j.type = d.type;
    j.body_a = sa;
    j.body_b = sb;
    j.hinge = d.hinge;
    j.distance = d.distance;
    j.swing_twist = d.swing_twist;
    j.prismatic = d.prismatic;
    j.motor = d.motor;
    j.motor.angular_offset.normalize();
    j.collide_connected = d.collide_connected;
    const bool world_frame = d.anchors.frame == JointFrame::World;
    // Anchors are given in the shape's frame (local) or in world; kept relative to the centre of mass.
    j.local_a = world_frame ? Vec3(qa.conjugate() * (d.anchors.a - b.x[sa])) : Vec3(d.anchors.a - b.local_com[sa]);
    j.local_b = world_frame ? Vec3(qb.conjugate() * (d.anchors.b - b.x[sb])) : Vec3(d.anchors.b - b.local_com[sb]);
    if (d.type == JointType::Hinge || d.type == JointType::SwingTwist) {
        const bool hinge = d.type == JointType::Hinge;
        const Vec3 axis_a = hinge ? d.hinge.axis_a : d.swing_twist.twist_axis_a;
        const Vec3 axis_b = hinge ? d.hinge.axis_b : d.swing_twist.twist_axis_b;
        const Vec3 wa = world_frame ? axis_a.normalized() : Vec3(qa * axis_a.normalized());
        const Vec3 wb = world_frame ? axis_b.normalized() : Vec3(qb * axis_b.normalized());
        j.axis_a = qa.conjugate() * wa;
        j.axis_b = qb.conjugate() * wb;
        // Angle references: one world perpendicular seen from both bodies, so the angle is 0 now.
        const Vec3 ra = perpendicular(wa);
        Vec3 rb = ra - wb * wb.dot(ra);
        rb = rb.norm() > 1e-6 ? Vec3(rb.normalized()) : perpendicular(wb);
        j.ref_a = qa.conjugate() * ra;
        j.ref_b = qb.conjugate() * rb;
    }
    j.reference = (qa.conjugate() * qb).normalized();
    if (d.type == JointType::Prismatic) {
        const Vec3 axis = world_frame ? d.prismatic.axis_a.normalized() : Vec3(qa * d.prismatic.axis_a.normalized());
        j.axis_a = qa.conjugate() * axis;
        j.ref_a = qa.conjugate() * perpendicular(axis);
        const Vec3 pa = b.x[sa] + qa * j.local_a, pb = b.x[sb] + qb * j.local_b;
        j.rest_length = axis.dot(pb - pa);
    }
    if (d.type == JointType::Distance) {
        const Vec3 pa = b.x[sa] + qa * j.local_a, pb = b.x[sb] + qb * j.local_b;
        j.rest_length = d.distance.rest_length < 0 ? (pb - pa).norm() : d.distance.rest_length;
    }
    return j;
}

const Joint& live_joint(const World& world, JointHandle h, const char* what) {
    if (!world.joints.is_live(h))
        throw Error(std::string(what) + ": " + to_string(h) + " is not a live joint (stale or foreign handle)");
    return world.joints.joint[h.index];
}

void block_pair(World& world, const Joint& j, int delta) {
    if (j.collide_connected) return;
    auto& pairs = world.joints.blocked_pairs;
    const std::uint64_t key = pair_key(j.body_a, j.body_b);
    if (delta > 0) {
        pairs[key] += 1;
        // A contact made before the joint would otherwise live until the bounds separate.
        if (const std::uint32_t* found = world.contact_index.find(key)) {
            const std::uint32_t position = *found;  // a copy: the removal moves the index's slots
            remove_contacts(world, {&position, 1});
        }
    } else if (auto it = pairs.find(key); it != pairs.end() && --it->second == 0) {
        pairs.erase(it);
    }
}

// dying: a body about to be destroyed with the joint (its proxy goes anyway).
void remove_joint(World& world, std::uint32_t slot, std::uint32_t dying = ~0u) {
    Joints& js = world.joints;
    const Joint& j = js.joint[slot];
    // The partners may have rested on this joint: let them move again.
    wake_body(world, j.body_a);
    wake_body(world, j.body_b);
    block_pair(world, j, -1);
    if (!j.collide_connected) {
        // The broadphase reports a pair only when a proxy is new or grew: re-adding one
        // body's proxy finds the pair again if the two still overlap.
        const bool b_first = world.bodies.type[j.body_b] != MotionType::Static && j.body_b != dying;
        const std::uint32_t body = b_first ? j.body_b : j.body_a;
        if (body != dying) {
            remove_proxy(world, body);
            add_proxy(world, body);
        }
    }
    if (j.type == JointType::Motor) world.joint_targets.remove_motor(js.handle(slot));
    js.alive[slot] = 0;
    js.live -= 1;
    js.free_slots.push_back(slot);
    js.awake_dirty = true;
}

}  // namespace

const std::vector<std::uint32_t>& awake_joints(World& world) {
    Joints& js = world.joints;
    if (js.awake_dirty) {
        js.awake_list.clear();
        for (std::uint32_t slot = 0; slot < js.capacity(); ++slot) {
            if (js.alive[slot] && !js.joint[slot].sleeping) js.awake_list.push_back(slot);
        }
        js.awake_dirty = false;
    }
    return js.awake_list;
}

void destroy_joints_of(World& world, std::uint32_t body_slot) {
    Joints& js = world.joints;
    if (js.live == 0) return;
    for (std::uint32_t slot = 0; slot < js.capacity(); ++slot) {
        if (js.alive[slot] && (js.joint[slot].body_a == body_slot || js.joint[slot].body_b == body_slot)) {
            remove_joint(world, slot, body_slot);
        }
    }
}

JointHandle Space::create_joint(const JointDesc& desc) {
    const AccessGate::Structure access(m_world->gate, "create_joint");
    World& w = *m_world;
    validate(w, desc);
    Joint joint = make_joint(w, desc);

    Joints& js = w.joints;
    std::uint32_t slot;
    if (!js.free_slots.empty()) {
        slot = js.free_slots.back();
        js.free_slots.pop_back();
    } else {
        slot = js.capacity();
        js.generation.push_back(0);
        js.alive.push_back(0);
        js.joint.emplace_back();
        js.desc.emplace_back();
    }
    js.generation[slot] += 1;
    if (js.generation[slot] == 0) js.generation[slot] = 1;  // 2^32 reuses: skip the invalid generation
    js.alive[slot] = 1;
    js.live += 1;
    // Wake first: a sleeping island revives its contacts, and the joint starts awake.
    wake_body(w, joint.body_a);
    wake_body(w, joint.body_b);
    js.joint[slot] = joint;
    js.desc[slot] = desc;
    js.awake_dirty = true;
    block_pair(w, joint, +1);
    if (joint.type == JointType::Motor) w.joint_targets.add_motor(js.handle(slot));
    return js.handle(slot);
}

void Space::destroy_joint(JointHandle joint) {
    const AccessGate::Structure access(m_world->gate, "destroy_joint");
    live_joint(*m_world, joint, "destroy_joint");
    remove_joint(*m_world, joint.index);
}

bool Space::contains(JointHandle joint) const noexcept { return m_world->joints.is_live(joint); }
std::size_t Space::joint_count() const noexcept { return m_world->joints.live; }

JointDesc Space::joint_desc(JointHandle joint) const {
    const AccessGate::Structure access(m_world->gate, "joint_desc");
    live_joint(*m_world, joint, "joint_desc");
    return m_world->joints.desc[joint.index];
}

void Space::set_hinge_motor(JointHandle handle, bool enable, Real speed, Real max_torque) {
    const AccessGate::Structure access(m_world->gate, "set_hinge_motor");
    World& w = *m_world;
    live_joint(w, handle, "set_hinge_motor");
    Joint& j = w.joints.joint[handle.index];
    if (j.type != JointType::Hinge)
        throw Error("set_hinge_motor: " + to_string(handle) + " is a " + to_string(j.type) + " joint");
    require_within(speed, kMaxCoordinate, "set_hinge_motor", "speed");
    check_non_negative(max_torque, "set_hinge_motor", "max_torque");
    if (j.hinge.enable_motor != enable) j.motor_impulse = 0;
    j.hinge.enable_motor = enable;
    j.hinge.motor_speed = speed;
    j.hinge.max_motor_torque = max_torque;
    w.joints.desc[handle.index].hinge = j.hinge;
    wake_body(w, j.body_a);
    wake_body(w, j.body_b);
}

JointError Space::internal_joint_error(JointHandle handle) const {
    const AccessGate::Structure access(m_world->gate, "internal_joint_error");
    const World& w = *m_world;
    const Joint& j = live_joint(w, handle, "internal_joint_error");
    const Bodies& b = w.bodies;
    const Quat qa = b.q[j.body_a], qb = b.q[j.body_b];
    const Vec3 pa = b.x[j.body_a] + qa * j.local_a, pb = b.x[j.body_b] + qb * j.local_b;
    JointError e;
    switch (j.type) {
        case JointType::BallSocket: e.linear = (pb - pa).norm(); break;
        case JointType::Hinge: {
            e.linear = (pb - pa).norm();
            const Vec3 a1 = qa * j.axis_a, a2 = qb * j.axis_b;
            e.angular = std::atan2(a1.cross(a2).norm(), a1.dot(a2));
            break;
        }
        case JointType::Fixed: {
            e.linear = (pb - pa).norm();
            const Quat error = qb * j.reference.conjugate() * qa.conjugate();
            e.angular = 2 * std::atan2(error.vec().norm(), std::abs(error.w()));
            break;
        }
        case JointType::Distance: {
            const Real length = (pb - pa).norm();
            const DistanceParams& p = j.distance;
            if (!p.enable_spring || (p.enable_limit && p.min_length >= p.max_length)) {
                e.linear = std::abs(length - (p.enable_spring ? p.min_length : j.rest_length));
            } else if (p.enable_limit) {
                e.linear = std::max({Real(0), p.min_length - length, length - p.max_length});
            }
            break;
        }
        case JointType::SwingTwist: {
            e.linear = (pb - pa).norm();
            const SwingTwistAngles angles = swing_twist_angles(qa * j.axis_a, qb * j.axis_b, qa * j.ref_a,
                                                               qb * j.ref_b);
            e.angular = swing_twist_violation(angles, j.swing_twist);
            break;
        }
        case JointType::Prismatic: {
            const PrismaticParams& p = j.prismatic;
            const PrismaticOffset offset = prismatic_offset(j, qa * j.axis_a, pa, pb);
            e.linear = offset.off_axis;
            if (p.enable_limit) {
                e.linear += std::max(
                    {Real(0), p.lower_translation - offset.translation, offset.translation - p.upper_translation});
            }
            const Quat error = qb * j.reference.conjugate() * qa.conjugate();
            e.angular = 2 * std::atan2(error.vec().norm(), std::abs(error.w()));
            break;
        }
        case JointType::Motor: {
            const MotorParams& p = j.motor;
            e.linear = (pb - (pa + qa * p.linear_offset)).norm();
            if (p.max_torque > 0) {
                const Quat error = qb * (p.angular_offset * j.reference).conjugate() * qa.conjugate();
                e.angular = 2 * std::atan2(error.vec().norm(), std::abs(error.w()));
            }
            break;
        }
    }
    return e;
}

Real Space::internal_hinge_angle(JointHandle handle) const {
    const AccessGate::Structure access(m_world->gate, "internal_hinge_angle");
    const World& w = *m_world;
    const Joint& j = live_joint(w, handle, "internal_hinge_angle");
    if (j.type != JointType::Hinge)
        throw Error("internal_hinge_angle: " + to_string(handle) + " is a " + to_string(j.type) + " joint");
    const Quat qa = w.bodies.q[j.body_a], qb = w.bodies.q[j.body_b];
    const Vec3 axis = qa * j.axis_a, ra = qa * j.ref_a, rb = qb * j.ref_b;
    return std::atan2(axis.dot(ra.cross(rb)), ra.dot(rb));
}

}  // namespace spindle
