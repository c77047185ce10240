// The checks of the public API's input, one function per rule and per struct, so that a
// rule and its message live in one place. Every message reads
// "<who>: <field> <rule>, got <value>", e.g. "solver: damping_ratio must be finite and >= 0, got inf".
#pragma once

#include <string>

#include <spindle/engine/body.hpp>
#include <spindle/engine/settings.hpp>
#include <spindle/engine/shape.hpp>

#include "collision/error_text.hpp"  // kMaxCoordinate

namespace spindle {

class MotionStateManager;

// Throws spindle::Error("<who>: <field> <rule>, got <got>").
[[noreturn]] void reject_field(const char* who, const std::string& field, const char* rule, const std::string& got);

void check_finite(Real value, const char* who, const char* field);
void check_finite(const Vec3& value, const char* who, const char* field);
// Finite and within kMaxCoordinate of the origin in every axis.
void check_position(const Vec3& value, const char* who, const char* field);
void check_non_negative(Real value, const char* who, const char* field);  // finite and >= 0
void check_positive(Real value, const char* who, const char* field);      // finite and > 0
void check_at_least(int value, int least, const char* who, const char* field);
void check_direction(const Vec3& value, const char* who, const char* field);    // finite and non-zero
void check_orientation(const Quat& value, const char* who, const char* field);  // finite and non-zero
void check_layer(std::uint32_t value, const char* who, const char* field);      // < kLayerCount
// A buffered write's handle: "<who>: body 3 (generation 1) is not a live body ...". Lock-free
// (published_generation), so a thread holding the motion-state lock can still write.
void check_handle_for_write(const MotionStateManager& manager, BodyHandle body, const char* who);

// Settings, the same for the Space constructor and each setter (who: "time_step",
// "solver", "sleep", "events"; gravity says "gravity must be finite").
void validate(const TimeStepSettings& settings);
void validate(const SolverSettings& settings);
void validate(const SleepSettings& settings);
void validate(const EventSettings& settings);
void validate(const CapacitySettings& settings);
void validate_gravity(const Vec3& gravity);
void validate(const SpaceSettings& settings);

// A shape as create_body receives it (its fields are public, so a hand-built one may
// hold anything): the type in range and the fields that type uses ("shape.radius ...").
void validate(const Shape& shape, const char* who);
// Everything create_body needs to know is valid, checked before anything changes.
void validate(const BodyDesc& desc);
// The fields a motion-state write uses: position, orientation and the velocities
// (center_of_mass follows from the pose and is not read).
void validate(const MotionState& state, const char* who);

}  // namespace spindle
