// The checks of the public API's input (validation.hpp): settings, shapes, body
// descriptions and motion states.
#include "api/validation.hpp"

#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/error.hpp>

#include <algorithm>
#include <cmath>

#include "api/describe.hpp"

namespace spindle {

void reject_field(const char* who, const std::string& field, const char* rule, const std::string& got) {
    throw Error(std::string(who) + ": " + field + " " + rule + ", got " + got);
}

void check_finite(Real value, const char* who, const char* field) {
    if (!std::isfinite(value)) reject_field(who, field, "must be finite", number(value));
}

void check_finite(const Vec3& value, const char* who, const char* field) {
    if (!is_finite(value)) reject_field(who, field, "must be finite", vec(value));
}

// Positions stay within a billion metres of the origin: far enough for any game world,
// and near enough that squared distances, bounds and the step's sums stay finite.
void check_position(const Vec3& value, const char* who, const char* field) {
    if (!is_finite(value) || value.cwiseAbs().maxCoeff() > kMaxCoordinate) {
        reject_field(who, field, ("must be finite and within " + number(kMaxCoordinate) + " m of the origin").c_str(),
                     vec(value));
    }
}

void check_non_negative(Real value, const char* who, const char* field) {
    if (!(std::isfinite(value) && value >= 0)) reject_field(who, field, "must be finite and >= 0", number(value));
}

void check_positive(Real value, const char* who, const char* field) {
    if (!(std::isfinite(value) && value > 0)) reject_field(who, field, "must be finite and > 0", number(value));
}

void check_at_least(int value, int least, const char* who, const char* field) {
    if (value < least) {
        reject_field(who, field, ("must be >= " + std::to_string(least)).c_str(), std::to_string(value));
    }
}

void check_direction(const Vec3& value, const char* who, const char* field) {
    if (!is_finite(value) || value.norm() < 1e-9)
        reject_field(who, field, "must be a finite, non-zero vector", vec(value));
}

void check_orientation(const Quat& value, const char* who, const char* field) {
    if (!is_finite(value) || value.norm() < 1e-9) {
        reject_field(who, field, "must be a finite, non-zero quaternion",
                     "(w " + number(value.w()) + ", " + vec(value.vec()) + ")");
    }
    // Components past about 1e154 square to infinity: normalising divides by an infinite
    // norm and leaves the zero quaternion (a body turned by nothing, its inertia zeroed).
    if (!std::isfinite(value.norm())) {
        reject_field(who, field, "must have a finite norm (components below 1e154)",
                     "(w " + number(value.w()) + ", " + vec(value.vec()) + ")");
    }
}

void check_layer(std::uint32_t value, const char* who, const char* field) {
    if (value >= kLayerCount) {
        reject_field(who, field, ("must be < " + std::to_string(kLayerCount)).c_str(), std::to_string(value));
    }
}

// ---- settings ----

void validate(const TimeStepSettings& s) {
    const char* who = "time_step";
    check_positive(s.duration, who, "duration");
    check_at_least(s.max_steps_per_frame, 1, who, "max_steps_per_frame");
    check_at_least(s.min_steps_per_frame, 0, who, "min_steps_per_frame");
    if (s.min_steps_per_frame > s.max_steps_per_frame) {
        reject_field(who, "min_steps_per_frame", "must be <= max_steps_per_frame",
                     std::to_string(s.min_steps_per_frame) + " > " + std::to_string(s.max_steps_per_frame));
    }
}

void validate(const SolverSettings& s) {
    const char* who = "solver";
    check_at_least(s.substeps, 1, who, "substeps");
    check_at_least(s.iterations, 1, who, "iterations");
    check_at_least(s.relax_iterations, 0, who, "relax_iterations");
    check_non_negative(s.contact_hertz, who, "contact_hertz");
    check_non_negative(s.damping_ratio, who, "damping_ratio");
    check_non_negative(s.joint_hertz, who, "joint_hertz");
    check_non_negative(s.joint_damping_ratio, who, "joint_damping_ratio");
    check_non_negative(s.push_out_speed, who, "push_out_speed");
    check_non_negative(s.recovery_depth, who, "recovery_depth");
    check_non_negative(s.restitution_threshold, who, "restitution_threshold");
    check_non_negative(s.speculative_distance, who, "speculative_distance");
    check_non_negative(s.linear_slop, who, "linear_slop");
    check_positive(s.max_linear_speed, who, "max_linear_speed");
    check_positive(s.max_angular_speed, who, "max_angular_speed");
}

void validate(const SleepSettings& s) {
    const char* who = "sleep";
    check_non_negative(s.time_to_sleep, who, "time_to_sleep");
    check_non_negative(s.linear_threshold, who, "linear_threshold");
    check_non_negative(s.angular_threshold, who, "angular_threshold");
}

void validate(const EventSettings& s) {
    const char* who = "events";
    check_non_negative(s.hit_speed, who, "hit_speed");
    if (s.max_queued < 1) reject_field(who, "max_queued", "must be >= 1", std::to_string(s.max_queued));
    if (s.max_contact_points < 1) {
        reject_field(who, "max_contact_points", "must be >= 1", std::to_string(s.max_contact_points));
    }
}

void validate(const CapacitySettings& s) {
    if (s.contact_count < 0 || s.contact_count > CapacitySettings::kMaxContactCount) {
        reject_field("capacity", "contact_count",
                     ("must be >= 0 and <= " + std::to_string(CapacitySettings::kMaxContactCount)).c_str(),
                     std::to_string(s.contact_count));
    }
}

void validate_gravity(const Vec3& gravity) {
    if (!is_finite(gravity)) throw Error("gravity must be finite, got " + vec(gravity));
}

void validate(const SpaceSettings& s) {
    validate_gravity(s.gravity);
    validate(s.time_step);
    validate(s.solver);
    validate(s.sleep);
    validate(s.events);
    validate(s.capacity);
}

// ---- shapes and bodies ----

namespace {

// A shape's sizes are held to the positions' bound (kMaxCoordinate), for the same reason:
// bounds, squared distances and the tree's areas of a shape a 1e300 m across overflow
// (NaN poses, a corrupt tree). Sizes as the primitives' fields name them.
void check_size(Real value, const char* who, const char* field) {
    check_positive(value, who, field);
    if (value > kMaxCoordinate) {
        reject_field(who, field, ("must be at most " + number(kMaxCoordinate) + " m").c_str(), number(value));
    }
}

// A hull's, mesh's or compound's geometry, by its bounds in its own frame.
void check_extent(const Shape& s, const char* who, const char* field) {
    const Aabb local = s.bounds(Transform{Vec3::Zero(), Quat::Identity()});
    const Real reach = std::max(local.min.cwiseAbs().maxCoeff(), local.max.cwiseAbs().maxCoeff());
    if (!(reach <= kMaxCoordinate)) {
        reject_field(who, field, ("must lie within " + number(kMaxCoordinate) + " m of the shape's origin").c_str(),
                     "bounds " + vec(local.min) + " to " + vec(local.max));
    }
}

}  // namespace

void validate(const Shape& s, const char* who) {
    switch (s.type) {
        case ShapeType::Sphere: check_size(s.radius, who, "shape.radius"); return;
        case ShapeType::Capsule:
            check_size(s.half_height, who, "shape.half_height");
            check_size(s.radius, who, "shape.radius");
            return;
        case ShapeType::Box:
            if (!(is_finite(s.half_extents) && s.half_extents.minCoeff() > 0)) {
                reject_field(who, "shape.half_extents", "must be finite and > 0", vec(s.half_extents));
            }
            if (s.half_extents.maxCoeff() > kMaxCoordinate) {
                reject_field(who, "shape.half_extents", ("must be at most " + number(kMaxCoordinate) + " m").c_str(),
                             vec(s.half_extents));
            }
            return;
        case ShapeType::ConvexHull:
            if (!s.hull) reject_field(who, "shape.hull", "must be set for a convex hull (Shape::convex_hull)", "none");
            check_extent(s, who, "shape.hull");
            return;
        case ShapeType::Plane:
            check_direction(s.normal, who, "shape.normal");
            check_finite(s.offset, who, "shape.offset");
            if (std::abs(s.offset) > kMaxCoordinate * s.normal.norm()) {
                reject_field(who, "shape.offset",
                             ("must put the plane within " + number(kMaxCoordinate) + " m of the origin").c_str(),
                             number(s.offset));
            }
            return;
        case ShapeType::TriangleMesh:
            if (!s.mesh)
                reject_field(who, "shape.mesh", "must be set for a triangle mesh (Shape::triangle_mesh)", "none");
            check_extent(s, who, "shape.mesh");
            return;
        case ShapeType::Compound:
            if (!s.parts) reject_field(who, "shape.parts", "must be set for a compound (Shape::compound)", "none");
            check_extent(s, who, "shape.parts");
            return;
        case ShapeType::Count: break;
    }
    reject_field(who, "shape.type", "must be a shape type", std::to_string(static_cast<int>(s.type)));
}

void validate(const BodyDesc& d) {
    const char* who = "create_body";
    if (d.type != MotionType::Static && d.type != MotionType::Kinematic && d.type != MotionType::Dynamic) {
        reject_field(who, "type", "must be Static, Kinematic or Dynamic", std::to_string(static_cast<int>(d.type)));
    }
    validate(d.shape, who);
    if (d.shape.static_only() && d.type != MotionType::Static) {
        throw Error(std::string(who) + ": a " + to_string(d.shape.type) + " shape can only belong to a static body");
    }
    check_position(d.position, who, "position");
    check_orientation(d.orientation, who, "orientation");
    check_finite(d.linear_velocity, who, "linear_velocity");
    check_finite(d.angular_velocity, who, "angular_velocity");
    check_non_negative(d.mass, who, "mass");
    check_non_negative(d.density, who, "density");
    // A dynamic body's mass comes from its density unless given.
    if (d.type == MotionType::Dynamic && d.mass == 0 && d.density == 0) {
        reject_field(who, "density", "must be > 0 when mass is 0", number(d.density));
    }
    check_non_negative(d.friction, who, "friction");
    check_non_negative(d.restitution, who, "restitution");
    check_non_negative(d.rolling_resistance, who, "rolling_resistance");
    check_finite(d.gravity_scale, who, "gravity_scale");
    check_non_negative(d.linear_damping, who, "linear_damping");
    check_non_negative(d.angular_damping, who, "angular_damping");
    check_layer(d.layer, who, "layer");
}

// The published generation of a slot is exact (creation and destruction publish at once),
// so a handle that does not match it names no live body: stale, never made, or from
// another space.
void check_handle_for_write(const MotionStateManager& manager, BodyHandle body, const char* who) {
    if (body.generation == 0 || manager.published_generation(body.index) != body.generation)
        throw Error(std::string(who) + ": " + to_string(body) + " is not a live body (stale or foreign handle)");
}

void validate(const MotionState& s, const char* who) {
    check_position(s.position, who, "position");
    check_orientation(s.orientation, who, "orientation");
    check_finite(s.linear_velocity, who, "linear_velocity");
    check_finite(s.angular_velocity, who, "angular_velocity");
}

}  // namespace spindle
