// Motor and mouse joint targets written while the space runs (Space::set_motor_target,
// set_mouse_target): a drag moves its target every frame from the game thread. Kept
// apart from the body write buffer, which is striped by body slot, and under one small
// lock: few joints are driven at once. Also the registry of live motor joints the
// setters check handles against, since the joint store itself is the update thread's.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <spindle/engine/joint.hpp>

namespace spindle {

struct World;

struct JointTargetWrite {
    JointHandle joint;
    Vec3 linear = Vec3::Zero();  // offset in A's frame, or a world point (world_point)
    Quat angular = Quat::Identity();
    bool world_point = false;  // a mouse target: the angular offset stays
};

class JointTargets {
public:
    // Update thread (create_joint, destroy_joint): a motor joint's slot and generation.
    void add_motor(JointHandle joint);
    void remove_motor(JointHandle joint);
    // Any thread: throws spindle::Error naming `who` unless `joint` is a live motor joint.
    void push(const JointTargetWrite& write, const char* who);
    // Update thread: the writes since the last drain, one per joint (the last), in the
    // order their joints were first written. Free while nothing was written.
    void drain(std::vector<JointTargetWrite>& out);

private:
    std::mutex m_lock;
    std::unordered_map<std::uint32_t, std::uint32_t> m_motors;  // slot -> generation
    std::vector<JointTargetWrite> m_pending;
    std::atomic<bool> m_any{false};
};

// ApplyWrites: the drained targets into their joints (stages/buffering.cpp).
void apply_joint_targets(World& world);

}  // namespace spindle
