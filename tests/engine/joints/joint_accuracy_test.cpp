// Joints against analytic answers (pendulum and spring periods) and joint error under
// hard loads (a 1000:1 mass on a chain, a long chain), with the numbers printed.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "joint_scenes.hpp"

using namespace spindle;
using namespace spindle::test;

namespace {

// Times at which f(step) changes sign, linearly interpolated between steps.
class ZeroCrossings {
public:
    explicit ZeroCrossings(double dt) : m_dt(dt) {}
    void add(double value) {
        if (m_steps > 0 && (m_previous < 0) != (value < 0)) {
            m_times.push_back(m_dt * (m_steps - 1 + m_previous / (m_previous - value)));
        }
        m_previous = value;
        ++m_steps;
    }
    const std::vector<double>& times() const { return m_times; }
    // Full periods from the first to the last crossing (two crossings a period).
    double period() const {
        const auto n = m_times.size();
        return n < 3 ? 0 : 2 * (m_times.back() - m_times.front()) / static_cast<double>(n - 1);
    }

private:
    double m_dt;
    double m_previous = 0;
    long m_steps = 0;
    std::vector<double> m_times;
};

}  // namespace

TEST(JointAccuracy, BallSocketPendulumPeriodWithinOnePercent) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const double length = 1, theta0 = 0.1;
    const Vec3 pivot(0, 2, 0);
    const BodyHandle anchor = add_static(space, pivot);
    const BodyHandle bob = add_sphere(space, pivot + length * Vec3(std::sin(theta0), -std::cos(theta0), 0), 0.05, 1);
    const JointHandle joint = space.create_joint(JointDesc::ball_socket_at(anchor, bob, pivot));

    ZeroCrossings crossings(1.0 / 60.0);
    double worst_error = 0;
    for (int i = 0; i < 60 * 11; ++i) {  // about five periods
        space.update();
        crossings.add(space.internal_position(bob).x() - pivot.x());
        worst_error = std::max(worst_error, space.internal_joint_error(joint).linear);
    }
    ASSERT_GE(crossings.times().size(), 10u);
    const double expected = 2 * kPi * std::sqrt(length / kG);
    const double relative = std::abs(crossings.period() - expected) / expected;
    std::printf("pendulum: period %.5f s, small-angle 2pi sqrt(L/g) %.5f s, error %.3f%%, worst joint error %.2e m\n",
                crossings.period(), expected, 100 * relative, worst_error);
    EXPECT_LT(relative, 0.01);
    EXPECT_LT(worst_error, 1e-3);
}

TEST(JointAccuracy, DistanceSpringPeriodMatchesTwoPiSqrtMOverK) {
    Space space;
    space.set_gravity(Vec3::Zero());
    space.set_sleep(SleepSettings{.enabled = false});
    const double mass = 2, hertz = 1, rest = 1;
    const BodyHandle anchor = add_static(space, Vec3::Zero());
    const BodyHandle body = add_sphere(space, Vec3(rest + 0.2, 0, 0), 0.1, mass);
    JointDesc d = JointDesc::distance_between(anchor, body, Vec3::Zero(), Vec3(rest + 0.2, 0, 0));
    d.distance.rest_length = rest;
    d.distance.enable_spring = true;
    d.distance.spring_hertz = hertz;
    space.create_joint(d);

    ZeroCrossings crossings(1.0 / 60.0);
    for (int i = 0; i < 60 * 5; ++i) {
        space.update();
        crossings.add(space.internal_position(body).x() - rest);
    }
    // The spring's stiffness is k = m (2 pi f)^2 for the mass it moves.
    const double k = mass * std::pow(2 * kPi * hertz, 2);
    const double expected = 2 * kPi * std::sqrt(mass / k);
    const double relative = std::abs(crossings.period() - expected) / expected;
    std::printf("spring: period %.5f s, 2pi sqrt(m/k) %.5f s, error %.3f%%\n", crossings.period(), expected,
                100 * relative);
    EXPECT_LT(relative, 0.03);
}

// A 10-bar chain (1 kg bars) hanging a 1000 kg ball, with 8 substeps. Soft joints are
// springs for their effective mass: a load F stretches one by about F / (m_eff w^2),
// w = 2 pi joint_hertz. The joint between bars 4 and 5 (m_eff 0.5 kg) carries the ball
// and five bars.
namespace {

struct HeavyChainRun {
    double worst = 0;      // largest error of any joint over the run
    double mean = 0;       // the middle joint's stretch, averaged over the run
    double predicted = 0;  // its stretch at rest by the spring model
};

HeavyChainRun run_heavy_chain(double joint_hertz, const Vec3& push) {
    SolverSettings solver;
    solver.substeps = 8;
    solver.joint_hertz = joint_hertz;
    Space space;
    space.set_solver(solver);
    space.set_sleep(SleepSettings{.enabled = false});
    const Chain chain = make_chain(space, Vec3(0, 5, 0), -Vec3::UnitY(), 10, 0.25, 1, 1000);
    space.set_linear_velocity(chain.links.back(), push);
    HeavyChainRun run;
    const int steps = 600;
    for (int i = 0; i < steps; ++i) {
        space.update();
        const double error = max_linear_error(space, chain.joints);
        EXPECT_TRUE(std::isfinite(error)) << "step " << i;
        if (!std::isfinite(error)) break;
        run.worst = std::max(run.worst, error);
        run.mean += space.internal_joint_error(chain.joints[5]).linear / steps;
    }
    const double stiffest = 0.25 * 60 * solver.substeps;  // joint_hertz is capped at a quarter of the substep rate
    const double omega = 2 * kPi * (joint_hertz > 0 ? std::min(joint_hertz, stiffest) : stiffest);
    run.predicted = 1005 * kG / (0.5 * omega * omega);
    std::printf("1000:1 chain, %g Hz joints, 8 substeps, push %.1f m/s: worst joint error %.4f m; middle joint mean "
                "stretch %.4f m, spring model %.4f m\n",
                omega / (2 * kPi), push.norm(), run.worst, run.mean, run.predicted);
    return run;
}

}  // namespace

// At the default 60 Hz the chain holds (bounded, no NaN) but stretches ~14 cm a joint,
// as the model says. The ball drops into the springs once, so the worst error is about
// twice the rest stretch.
TEST(JointAccuracy, ThousandToOneChainStretchesAsItsSoftnessPredicts) {
    const HeavyChainRun run = run_heavy_chain(SolverSettings{}.joint_hertz, Vec3::Zero());
    EXPECT_NEAR(run.mean, run.predicted, 0.15 * run.predicted);
    EXPECT_LT(run.worst, 2.2 * run.predicted);
}

// The knob for heavy loads: joint_hertz 0 picks the stiffest stable joints, a quarter
// of the substep rate (120 Hz at 8 substeps), which hold the swinging 1000:1 chain to a
// few centimetres.
TEST(JointAccuracy, ChainHoldsAThousandToOneMassWithEightSubsteps) {
    const HeavyChainRun run = run_heavy_chain(0, Vec3(1, 0, 0));
    EXPECT_NEAR(run.mean, run.predicted, 0.15 * run.predicted);
    EXPECT_LT(run.worst, 2.2 * run.predicted);
    EXPECT_LT(run.worst, 0.08);
}

namespace {

// A 20-link chain released level: the free end whips through the bottom of the swing.
// Returns the worst joint error over 1000 steps and over the last 100.
std::pair<double, double> long_chain_errors(bool gyroscopic) {
    Space space;
    space.set_sleep(SleepSettings{.enabled = false});
    const Chain chain = make_chain(space, Vec3(0, 10, 0), Vec3::UnitX(), 20, 0.25, 1, 0, gyroscopic);
    double worst = 0, late = 0;
    for (int i = 0; i < 1000; ++i) {
        space.update();
        const double error = max_linear_error(space, chain.joints);
        EXPECT_TRUE(std::isfinite(error)) << "step " << i;
        worst = std::max(worst, error);
        if (i >= 900) late = std::max(late, error);
    }
    std::printf("20-link chain%s, 1000 steps: worst joint error %.4f m, over the last 100 steps %.4f m\n",
                gyroscopic ? " (gyroscopic links)" : "", worst, late);
    return {worst, late};
}

}  // namespace

TEST(JointAccuracy, LongChainErrorStaysBounded) {
    const auto [worst, late] = long_chain_errors(false);
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(late, 0.01);
}

// Thin links (ratio of inertias 20) that keep their angular momentum as they turn must
// keep their joints as well as links that do not.
TEST(JointAccuracy, LongChainOfGyroscopicLinksErrorStaysBounded) {
    const auto [worst, late] = long_chain_errors(true);
    EXPECT_LT(worst, 0.05);
    EXPECT_LT(late, 0.01);
}
