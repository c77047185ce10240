// The state check of SPINDLE_VALIDATE_STATE (stages/update.cpp): it names the first
// awake body whose state is not finite, the field and the stage. Called directly, so
// it is tested in every build, the option on or off.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "stages/stages.hpp"

using namespace spindle;

namespace {

// A world holding `n` awake bodies at rest, as far as the check reads it.
void add_bodies(World& w, std::uint32_t n) {
    Bodies& b = w.bodies;
    for (std::uint32_t i = 0; i < n; ++i) {
        b.generation.push_back(1);
        b.alive.push_back(1);
        b.x.push_back(Vec3::Zero());
        b.q.push_back(Quat::Identity());
        b.v.push_back(Vec3::Zero());
        b.w.push_back(Vec3::Zero());
        w.awake.push_back(i);
    }
}

std::string message_of(const World& w, Stage stage) {
    try {
        check_state(w, stage);
    } catch (const Error& e) {
        return e.what();
    }
    return "(passed)";
}

}  // namespace

TEST(StateCheck, PassesAFiniteState) {
    World w;
    add_bodies(w, 3);
    EXPECT_EQ(message_of(w, Stage::Solver), "(passed)");
}

TEST(StateCheck, NamesTheFirstBadBodyFieldAndStage) {
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    World w;
    add_bodies(w, 3);
    w.bodies.v[1] = Vec3(1, nan, 0);
    w.bodies.w[2] = Vec3(std::numeric_limits<Real>::infinity(), 0, 0);
    EXPECT_EQ(message_of(w, Stage::Solver),
              "state check: body 1 (generation 1) has a non-finite linear_velocity (1, nan, 0) after stage Solver");
    w.bodies.v[1] = Vec3::Zero();
    w.bodies.q[1].w() = nan;
    EXPECT_NE(message_of(w, Stage::Narrowphase).find("body 1 (generation 1) has a non-finite orientation"),
              std::string::npos);
    w.bodies.q[1] = Quat::Identity();
    EXPECT_EQ(
        message_of(w, Stage::ApplyWrites),
        "state check: body 2 (generation 1) has a non-finite angular_velocity (inf, 0, 0) after stage ApplyWrites");
    w.bodies.x[0] = Vec3(0, 0, -std::numeric_limits<Real>::infinity());
    EXPECT_NE(message_of(w, Stage::Record).find("body 0 (generation 1) has a non-finite center_of_mass"),
              std::string::npos);
}
