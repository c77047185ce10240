// Invalid settings: every field of every settings struct, through its setter and through
// the Space constructor, with NaN, infinities, a negative value and zero. A rejection
// names the field, the constructor and the setter say the same, and the space is unchanged.
#include <climits>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "invalid_input.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

template <typename S>
struct RealField {
    const char* name;
    Real S::*member;
    Rule rule;
};

template <typename S>
struct IntField {
    const char* name;
    int S::*member;
    int least;  // the smallest value accepted
};

// Tries every field of settings struct S through `set` (a setter on a space) and
// `compose` (puts S into SpaceSettings for the constructor).
template <typename S, typename Set, typename Compose>
void try_fields(const std::vector<RealField<S>>& reals, const std::vector<IntField<S>>& ints, Set set,
                Compose compose) {
    auto try_value = [&](const std::string& name, const std::string& trial, bool accepted, const S& bad) {
        Scene scene = make_scene();
        Scene twin = make_scene();
        auto setter = [&] { set(*scene.space, bad); };
        SpaceSettings all;
        compose(all, bad);
        auto construct = [&] { Space space(all); };
        if (accepted) {
            expect_accepted(setter, name, trial);
            expect_accepted(construct, name, trial);
            return;
        }
        expect_rejected(*scene.space, *twin.space, setter, name, trial);
        // One check for both: the constructor says exactly what the setter says.
        EXPECT_EQ(error_of(construct), error_of(setter)) << name << " = " << trial;
    };
    for (const RealField<S>& f : reals) {
        for (const Trial& t : kTrials) {
            S bad;
            bad.*f.member = t.value;
            try_value(f.name, t.name, accepts(f.rule, t.value), bad);
        }
    }
    for (const IntField<S>& f : ints) {
        for (const int value : {INT_MIN, -1, 0}) {
            S bad;
            bad.*f.member = value;
            try_value(f.name, std::to_string(value), value >= f.least, bad);
        }
    }
}

}  // namespace

TEST(InvalidSettings, TimeStepFieldsAreCheckedByConstructorAndSetter) {
    try_fields<TimeStepSettings>(
        {{"duration", &TimeStepSettings::duration, Rule::Positive}},
        {{"max_steps_per_frame", &TimeStepSettings::max_steps_per_frame, 1},
         {"min_steps_per_frame", &TimeStepSettings::min_steps_per_frame, 0}},
        [](Space& s, const TimeStepSettings& v) { s.set_time_step(v); },
        [](SpaceSettings& all, const TimeStepSettings& v) { all.time_step = v; });
}

TEST(InvalidSettings, MinStepsAboveMaxStepsIsRejected) {
    Scene scene = make_scene();
    Scene twin = make_scene();
    TimeStepSettings bad;
    bad.max_steps_per_frame = 2;
    bad.min_steps_per_frame = 3;
    expect_rejected(
        *scene.space, *twin.space, [&] { scene.space->set_time_step(bad); }, "min_steps_per_frame", "3");
}

TEST(InvalidSettings, SolverFieldsAreCheckedByConstructorAndSetter) {
    using S = SolverSettings;
    try_fields<S>(
        {
            {"contact_hertz", &S::contact_hertz, Rule::NonNegative},
            {"damping_ratio", &S::damping_ratio, Rule::NonNegative},
            {"joint_hertz", &S::joint_hertz, Rule::NonNegative},
            {"joint_damping_ratio", &S::joint_damping_ratio, Rule::NonNegative},
            {"push_out_speed", &S::push_out_speed, Rule::NonNegative},
            {"recovery_depth", &S::recovery_depth, Rule::NonNegative},
            {"restitution_threshold", &S::restitution_threshold, Rule::NonNegative},
            {"speculative_distance", &S::speculative_distance, Rule::NonNegative},
            {"linear_slop", &S::linear_slop, Rule::NonNegative},
        },
        {{"substeps", &S::substeps, 1},
         {"iterations", &S::iterations, 1},
         {"relax_iterations", &S::relax_iterations, 0}},
        [](Space& s, const S& v) { s.set_solver(v); }, [](SpaceSettings& all, const S& v) { all.solver = v; });
}

TEST(InvalidSettings, SleepFieldsAreCheckedByConstructorAndSetter) {
    using S = SleepSettings;
    try_fields<S>(
        {
            {"time_to_sleep", &S::time_to_sleep, Rule::NonNegative},
            {"linear_threshold", &S::linear_threshold, Rule::NonNegative},
            {"angular_threshold", &S::angular_threshold, Rule::NonNegative},
        },
        {}, [](Space& s, const S& v) { s.set_sleep(v); }, [](SpaceSettings& all, const S& v) { all.sleep = v; });
}

TEST(InvalidSettings, GravityIsCheckedByConstructorAndSetter) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const Trial& t : kTrials) {
            Vec3 gravity(0, -9.81, 0);
            gravity[axis] = t.value;
            Scene scene = make_scene();
            Scene twin = make_scene();
            auto setter = [&] { scene.space->set_gravity(gravity); };
            SpaceSettings all;
            all.gravity = gravity;
            auto construct = [&] { Space space(all); };
            if (accepts(Rule::Finite, t.value)) {
                expect_accepted(setter, "gravity", t.name);
                expect_accepted(construct, "gravity", t.name);
                continue;
            }
            expect_rejected(*scene.space, *twin.space, setter, "gravity", t.name);
            EXPECT_EQ(error_of(construct), error_of(setter));
        }
    }
}

// The message gives the struct, the field, the rule and the value.
TEST(InvalidSettings, MessageNamesStructFieldRuleAndValue) {
    Space space;
    SolverSettings solver;
    solver.damping_ratio = kInf;
    EXPECT_EQ(error_of([&] { space.set_solver(solver); }), "solver: damping_ratio must be finite and >= 0, got inf");
    SleepSettings sleep;
    sleep.time_to_sleep = -1;
    EXPECT_EQ(error_of([&] { space.set_sleep(sleep); }), "sleep: time_to_sleep must be finite and >= 0, got -1");
    EXPECT_EQ(error_of([&] { space.set_gravity(Vec3(0, kNaN, 0)); }), "gravity must be finite, got (0, nan, 0)");
}

// update(dt): any finite dt >= 0 is taken; the rest is an error that changes nothing.
TEST(InvalidSettings, UpdateRejectsNonFiniteAndNegativeDt) {
    for (const Trial& t : kTrials) {
        for (const bool internal : {false, true}) {
            SpaceSettings settings;
            settings.time_step.use_internal_time_stepping = internal;
            Scene scene = make_scene(settings);
            Scene twin = make_scene(settings);
            auto change = [&] { scene.space->update(t.value); };
            if (accepts(Rule::NonNegative, t.value)) {
                expect_accepted(change, "dt", t.name);
            } else {
                expect_rejected(*scene.space, *twin.space, change, "dt", t.name);
            }
        }
    }
}

// The contact count hint has no setter (it sizes a level's build): the constructor checks
// it, naming the struct, the field, the bounds and the value.
TEST(InvalidSettings, CapacityContactCountIsCheckedByTheConstructor) {
    constexpr std::int64_t kMost = CapacitySettings::kMaxContactCount;
    for (const std::int64_t bad : {std::numeric_limits<std::int64_t>::min(), std::int64_t{-1}, kMost + 1,
                                   std::numeric_limits<std::int64_t>::max()}) {
        SpaceSettings all;
        all.capacity.contact_count = bad;
        EXPECT_EQ(error_of([&] { Space space(all); }),
                  "capacity: contact_count must be >= 0 and <= 4294967295, got " + std::to_string(bad));
    }
    for (const std::int64_t good : {std::int64_t{0}, std::int64_t{60000}, kMost}) {
        SpaceSettings all;
        all.capacity.contact_count = good;
        expect_accepted([&] { Space space(all); }, "contact_count", std::to_string(good));
    }
}
