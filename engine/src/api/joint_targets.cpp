// JointTargets and the motor and mouse target setters (joint_targets.hpp).
#include "api/joint_targets.hpp"

#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include "api/validation.hpp"
#include "stages/stages.hpp"
#include "world.hpp"

namespace spindle {

void JointTargets::add_motor(JointHandle joint) {
    const std::scoped_lock guard(m_lock);
    m_motors[joint.index] = joint.generation;
}

void JointTargets::remove_motor(JointHandle joint) {
    const std::scoped_lock guard(m_lock);
    m_motors.erase(joint.index);
}

void JointTargets::push(const JointTargetWrite& write, const char* who) {
    const std::scoped_lock guard(m_lock);
    const auto it = m_motors.find(write.joint.index);
    if (write.joint.generation == 0 || it == m_motors.end() || it->second != write.joint.generation) {
        throw Error(std::string(who) + ": " + to_string(write.joint) + " is not a live motor joint");
    }
    // Few joints are driven at once: a scan finds the joint's earlier write.
    for (JointTargetWrite& pending : m_pending) {
        if (pending.joint == write.joint) {
            pending = write;
            return;
        }
    }
    m_pending.push_back(write);
    m_any.store(true, std::memory_order_release);
}

void JointTargets::drain(std::vector<JointTargetWrite>& out) {
    out.clear();
    if (!m_any.load(std::memory_order_acquire)) return;
    const std::scoped_lock guard(m_lock);
    out.swap(m_pending);
    m_any.store(false, std::memory_order_relaxed);
}

void apply_joint_targets(World& world) {
    world.joint_target_writes.clear();
    world.joint_targets.drain(world.joint_target_writes);
    Joints& js = world.joints;
    const Bodies& b = world.bodies;
    for (const JointTargetWrite& write : world.joint_target_writes) {
        if (!js.is_live(write.joint) || js.joint[write.joint.index].type != JointType::Motor) {
            world.stats.writes_rejected += 1;  // destroyed after the write was made
            continue;
        }
        Joint& j = js.joint[write.joint.index];
        MotorParams& motor = j.motor;
        if (write.world_point) {
            // The target of B's anchor as an offset from A's anchor in A's frame, A as it is now.
            const Quat qa = b.q[j.body_a];
            motor.linear_offset = qa.conjugate() * (write.linear - (b.x[j.body_a] + qa * j.local_a));
        } else {
            motor.linear_offset = write.linear;
            motor.angular_offset = write.angular.normalized();
        }
        js.desc[write.joint.index].motor = motor;
        wake_body(world, j.body_a);
        wake_body(world, j.body_b);
        world.stats.writes_applied += 1;
    }
}

void Space::set_motor_target(JointHandle joint, const Vec3& linear_offset, const Quat& angular_offset) {
    const char* who = "set_motor_target";
    check_finite(linear_offset, who, "linear_offset");
    check_orientation(angular_offset, who, "angular_offset");
    m_world->joint_targets.push({joint, linear_offset, angular_offset, false}, who);
}

void Space::set_mouse_target(JointHandle joint, const Vec3& world_target) {
    const char* who = "set_mouse_target";
    check_position(world_target, who, "world_target");
    m_world->joint_targets.push({joint, world_target, Quat::Identity(), true}, who);
}

}  // namespace spindle
