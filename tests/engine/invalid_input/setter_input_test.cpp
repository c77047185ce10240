// Invalid writes: every buffered and internal setter, each component with NaN,
// infinities, a negative value and zero; and Entity's setters outside a space. A
// rejection names the field and leaves the space (and what it will do next) unchanged.
#include <spindle/engine/entity.hpp>

#include <functional>
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

using VectorSetter = std::function<void(Space&, BodyHandle, const Vec3&)>;

struct VectorWrite {
    const char* field;
    VectorSetter set;
};

const std::vector<VectorWrite>& vector_writes() {
    static const std::vector<VectorWrite> writes{
        {"position", [](Space& s, BodyHandle b, const Vec3& v) { s.set_position(b, v); }},
        {"linear_velocity", [](Space& s, BodyHandle b, const Vec3& v) { s.set_linear_velocity(b, v); }},
        {"angular_velocity", [](Space& s, BodyHandle b, const Vec3& v) { s.set_angular_velocity(b, v); }},
        {"force", [](Space& s, BodyHandle b, const Vec3& v) { s.add_force(b, v); }},
        {"torque", [](Space& s, BodyHandle b, const Vec3& v) { s.add_torque(b, v); }},
        {"impulse", [](Space& s, BodyHandle b, const Vec3& v) { s.apply_impulse(b, v); }},
        {"angular_impulse", [](Space& s, BodyHandle b, const Vec3& v) { s.apply_angular_impulse(b, v); }},
        {"force", [](Space& s, BodyHandle b, const Vec3& v) { s.add_force_at(b, v, Vec3(2, 3.5, 0)); }},
        {"point", [](Space& s, BodyHandle b, const Vec3& v) { s.add_force_at(b, Vec3(1, 0, 0), v); }},
        {"impulse", [](Space& s, BodyHandle b, const Vec3& v) { s.apply_impulse_at(b, v, Vec3(2, 3.5, 0)); }},
        {"point", [](Space& s, BodyHandle b, const Vec3& v) { s.apply_impulse_at(b, Vec3(1, 0, 0), v); }},
    };
    return writes;
}

void try_write(const std::function<void(Space&, BodyHandle)>& write, bool accepted, const std::string& field,
               const std::string& trial) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    auto change = [&] { write(*scene.space, scene.box); };
    if (accepted) {
        expect_accepted(change, field, trial);
    } else {
        expect_rejected(*scene.space, *twin.space, change, field, trial);
    }
}

// The fields of a MotionState a write uses, spoiled one component at a time.
struct StateField {
    const char* name;
    std::function<void(MotionState&, int axis, Real value)> spoil;
    int components;
};

const std::vector<StateField>& state_fields() {
    static const std::vector<StateField> fields{
        {"position", [](MotionState& s, int k, Real v) { s.position[k] = v; }, 3},
        {"orientation", [](MotionState& s, int k, Real v) { s.orientation.coeffs()[k] = v; }, 4},
        {"linear_velocity", [](MotionState& s, int k, Real v) { s.linear_velocity[k] = v; }, 3},
        {"angular_velocity", [](MotionState& s, int k, Real v) { s.angular_velocity[k] = v; }, 3},
    };
    return fields;
}

void try_motion_states(const std::function<void(Space&, BodyHandle, const MotionState&)>& set) {
    for (const StateField& f : state_fields()) {
        for (int k = 0; k < f.components; ++k) {
            for (const Trial& t : kTrials) {
                MotionState state;
                state.position = Vec3(1, 2, 3);
                state.linear_velocity = Vec3(1, 0, 0);
                f.spoil(state, k, t.value);
                // Zero in the orientation's w (coefficient 3) makes the zero quaternion.
                const bool zero_quaternion = std::string(f.name) == "orientation" && k == 3 && t.value == 0;
                const bool ok = accepts(Rule::Finite, t.value) && !zero_quaternion;
                try_write([&](Space& s, BodyHandle b) { set(s, b, state); }, ok, f.name, t.name);
            }
        }
    }
    MotionState zero;
    zero.orientation = Quat(0, 0, 0, 0);
    try_write([&](Space& s, BodyHandle b) { set(s, b, zero); }, false, "orientation", "zero");
}

}  // namespace

TEST(InvalidWrite, VectorSettersMustBeFinite) {
    for (const VectorWrite& w : vector_writes()) {
        for (int axis = 0; axis < 3; ++axis) {
            for (const Trial& t : kTrials) {
                Vec3 value(1, 2, 3);
                value[axis] = t.value;
                try_write([&](Space& s, BodyHandle b) { w.set(s, b, value); }, accepts(Rule::Finite, t.value), w.field,
                          t.name);
            }
        }
    }
}

TEST(InvalidWrite, OrientationMustBeFiniteAndNonZero) {
    for (int k = 0; k < 4; ++k) {
        for (const Trial& t : kTrials) {
            Quat q = Quat::Identity();
            q.coeffs()[k] = t.value;
            // Zero in w leaves the identity's axis part zero too: that is the zero quaternion.
            const bool ok = accepts(Rule::Finite, t.value) && !(k == 3 && t.value == 0);
            try_write([&](Space& s, BodyHandle b) { s.set_orientation(b, q); }, ok, "orientation", t.name);
        }
    }
}

TEST(InvalidWrite, MotionStateFieldsMustBeFinite) {
    try_motion_states([](Space& s, BodyHandle b, const MotionState& m) { s.set_motion_state(b, m); });
}

TEST(InvalidWrite, InternalMotionStateFieldsMustBeFinite) {
    try_motion_states([](Space& s, BodyHandle b, const MotionState& m) { s.set_internal_motion_state(b, m); });
}

TEST(InvalidWrite, CollisionFilterLayerMustBeBelowTheLayerCount) {
    for (std::uint32_t layer : {0u, kLayerCount - 1, kLayerCount, ~0u}) {
        try_write([&](Space& s, BodyHandle b) { s.set_collision_filter(b, layer, 7); }, layer < kLayerCount, "layer",
                  std::to_string(layer));
    }
}

// The real-valued changes after creation, each with BodyDesc's rule for its field.
TEST(InvalidWrite, RealSettersFollowTheirRules) {
    struct RealWrite {
        const char* field;
        Rule rule;
        std::function<void(Space&, BodyHandle, Real)> set;
    };
    const std::vector<RealWrite> writes{
        {"friction", Rule::NonNegative, [](Space& s, BodyHandle b, Real v) { s.set_friction(b, v); }},
        {"restitution", Rule::NonNegative, [](Space& s, BodyHandle b, Real v) { s.set_restitution(b, v); }},
        {"rolling_resistance", Rule::NonNegative,
         [](Space& s, BodyHandle b, Real v) { s.set_rolling_resistance(b, v); }},
        {"gravity_scale", Rule::Finite, [](Space& s, BodyHandle b, Real v) { s.set_gravity_scale(b, v); }},
        {"linear_damping", Rule::NonNegative, [](Space& s, BodyHandle b, Real v) { s.set_damping(b, v, 0); }},
        {"angular_damping", Rule::NonNegative, [](Space& s, BodyHandle b, Real v) { s.set_damping(b, 0, v); }},
    };
    for (const RealWrite& w : writes) {
        for (const Trial& t : kTrials) {
            try_write([&](Space& s, BodyHandle b) { w.set(s, b, t.value); }, accepts(w.rule, t.value), w.field, t.name);
        }
    }
}

TEST(InvalidWrite, LayerTableLayersMustBeBelowTheLayerCount) {
    for (std::uint32_t layer : {kLayerCount, ~0u}) {
        try_write([&](Space& s, BodyHandle) { s.set_layers_collide(layer, 0, false); }, false, "a must be < 32",
                  std::to_string(layer));
        try_write([&](Space& s, BodyHandle) { s.set_layers_collide(0, layer, false); }, false, "b must be < 32",
                  std::to_string(layer));
    }
}

TEST(InvalidWrite, MessageNamesTheFieldAndValue) {
    Scene scene = make_scene();
    MotionState state;
    state.linear_velocity = Vec3(1, kNaN, 0);
    EXPECT_EQ(error_of([&] { scene.space->set_motion_state(scene.box, state); }),
              "set_motion_state: linear_velocity must be finite, got (1, nan, 0)");
    EXPECT_EQ(error_of([&] { scene.space->set_internal_motion_state(scene.box, state); }),
              "set_internal_motion_state: linear_velocity must be finite, got (1, nan, 0)");
    EXPECT_EQ(error_of([&] { scene.space->apply_impulse(scene.box, Vec3(kInf, 0, 0)); }),
              "apply_impulse: impulse must be finite, got (inf, 0, 0)");
}

// Outside a space an Entity writes its values directly, with the same checks.
TEST(InvalidWrite, EntitySettersOutsideASpaceMustBeFinite) {
    const std::vector<std::pair<const char*, std::function<void(Entity&, const Vec3&)>>> setters{
        {"position", [](Entity& e, const Vec3& v) { e.set_position(v); }},
        {"linear_velocity", [](Entity& e, const Vec3& v) { e.set_linear_velocity(v); }},
        {"angular_velocity", [](Entity& e, const Vec3& v) { e.set_angular_velocity(v); }},
    };
    for (const auto& [field, set] : setters) {
        for (int axis = 0; axis < 3; ++axis) {
            for (const Trial& t : kTrials) {
                SCOPED_TRACE(std::string(field) + " = " + t.name);
                Entity entity;
                const MotionState before = entity.motion_state();
                Vec3 value(1, 2, 3);
                value[axis] = t.value;
                const std::string message = error_of([&] { set(entity, value); });
                if (accepts(Rule::Finite, t.value)) {
                    EXPECT_EQ(message, "(accepted)");
                    continue;
                }
                EXPECT_NE(message.find(field), std::string::npos) << message;
                const MotionState after = entity.motion_state();
                EXPECT_EQ(after.position, before.position);
                EXPECT_EQ(after.linear_velocity, before.linear_velocity);
                EXPECT_EQ(after.angular_velocity, before.angular_velocity);
            }
        }
    }
    Entity entity;
    EXPECT_NE(error_of([&] { entity.set_orientation(Quat(kNaN, 0, 0, 0)); }).find("orientation"), std::string::npos);
}
