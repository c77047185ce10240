// Joints solved eight at a time in floats (joint_lanes.cpp, with joint_swing_twist.cpp's
// and joint_hinge.cpp's angular rows) push their bodies as the scalar rows in doubles do
// (joint_solver.cpp, joint_swing_twist.cpp), lane for lane, empty lanes and all; joints of
// a locked body stay with the scalar rows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "solver/constraints.hpp"
#include "solver/joint_lanes.hpp"

using namespace spindle;

namespace {

// Random bodies: turned, moving and already moved, with uneven inertias (a general
// symmetric inverse inertia in world), masses over two decades. The last is the
// immovable partner of static bodies, as in a step.
RawRoomVector<SolverBody> random_bodies(int count, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1, 1), mass(0.5, 50);
    auto vec = [&] { return Vec3(unit(rng), unit(rng), unit(rng)); };
    RawRoomVector<SolverBody> bodies(static_cast<std::size_t>(count) + 1, SolverBody{});  // raw room: filled
    for (int i = 0; i < count; ++i) {
        SolverBody& b = bodies[static_cast<std::size_t>(i)];
        b.v = vec();
        b.w = 2 * vec();
        b.dp = 0.05 * vec();
        b.dq = Quat(1, 0.1 * unit(rng), 0.1 * unit(rng), 0.1 * unit(rng)).normalized();
        const double m = mass(rng);
        b.inv_mass = 1 / m;
        const Mat3 r = Quat(unit(rng), unit(rng), unit(rng), unit(rng)).normalized().toRotationMatrix();
        const Vec3 inertia = m * Vec3(0.1 + 0.2 * (1 + unit(rng)), 0.1 + 0.2 * (1 + unit(rng)), 0.3);
        b.inv_inertia = r * Mat3(inertia.cwiseInverse().asDiagonal()) * r.transpose();
        b.dynamic = true;
    }
    return bodies;
}

JointConstraint random_joint(std::uint32_t a, std::uint32_t b, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1, 1);
    auto vec = [&] { return Vec3(unit(rng), unit(rng), unit(rng)); };
    JointConstraint jc;
    jc.type = JointType::BallSocket;
    jc.a = a;
    jc.b = b;
    jc.ra = 0.5 * vec();
    jc.rb = 0.5 * vec();
    jc.delta_center = jc.ra - jc.rb + 0.02 * vec();  // the anchors 2 cm or so apart
    jc.linear_impulse = 3 * vec();
    return jc;
}

void expect_near(const Vec3& wide, const Vec3& scalar, const char* what, int joint) {
    const double tolerance = 1e-4 * std::max(1.0, scalar.norm());
    EXPECT_LT((wide - scalar).norm(), tolerance)
        << what << " of joint " << joint << ": lanes " << wide.transpose() << ", scalar " << scalar.transpose();
}

void expect_near(double wide, double scalar, const char* what, int joint) {
    EXPECT_LT(std::abs(wide - scalar), 1e-4 * std::max(1.0, std::abs(scalar)))
        << what << " of joint " << joint << ": lanes " << wide << ", scalar " << scalar;
}

// The scalar rows' side of a comparison: copies of the bodies and joints they pushed.
struct ScalarSide {
    RawRoomVector<SolverBody> bodies;
    std::vector<JointConstraint> joints;
};

// Prepares the packed lanes' blocks [0, blocks), then pushes them on scratch's bodies and
// joints [0, scalar_count) by the scalar rows on copies: a warm start, then solve, relax,
// solve; the lanes' impulses are stored back into scratch.joints.
ScalarSide push_both_ways(SolverScratch& scratch, std::uint32_t scalar_count, std::uint32_t blocks) {
    prepare_joint_lanes(scratch, 0, blocks);
    ScalarSide scalar{scratch.bodies, scratch.joints};
    const JointSolveParams solve{make_softness(60, 2, 1.0 / 240), 240, true};
    const JointSolveParams relax{solve.soft, solve.inv_h, false};
    EffectCounts wide_counts, scalar_counts;
    for (std::uint32_t k = 0; k < scalar_count; ++k) warm_start_joint(scalar.joints[k], scalar.bodies.data());
    for (WideJoint& wj : scratch.wide_joints) warm_start_joint_lanes(scratch, wj, scratch.bodies.data());
    for (const JointSolveParams& params : {solve, relax, solve}) {
        for (std::uint32_t k = 0; k < scalar_count; ++k)
            solve_joint(scalar.joints[k], scalar.bodies.data(), params, scalar_counts);
        for (WideJoint& wj : scratch.wide_joints)
            solve_joint_lanes(scratch, wj, scratch.bodies.data(), params, wide_counts);
    }
    store_joint_lane_impulses(scratch, 0, blocks);
    EXPECT_EQ(wide_counts.joints, scalar_counts.joints);
    return scalar;
}

// Every impulse of joints [0, count) and the velocities of their bodies, lanes against scalar.
void expect_pushed_alike(const SolverScratch& scratch, const ScalarSide& scalar, std::uint32_t count) {
    for (std::uint32_t k = 0; k < count; ++k) {
        const JointConstraint& jc = scalar.joints[k];
        const JointConstraint& wide = scratch.joints[k];
        const int i = static_cast<int>(k);
        expect_near(wide.linear_impulse, jc.linear_impulse, "point impulse", i);
        expect_near(wide.angular_impulse, jc.angular_impulse, "friction impulse", i);
        expect_near(wide.swing_impulse, jc.swing_impulse, "swing impulse", i);
        expect_near(wide.lower_impulse, jc.lower_impulse, "lower impulse", i);
        expect_near(wide.upper_impulse, jc.upper_impulse, "upper impulse", i);
        expect_near(wide.motor_impulse, jc.motor_impulse, "motor impulse", i);
        expect_near(wide.align_impulse.x(), jc.align_impulse.x(), "first alignment impulse", i);
        expect_near(wide.align_impulse.y(), jc.align_impulse.y(), "second alignment impulse", i);
        for (const std::uint32_t b : {jc.a, jc.b}) {
            expect_near(scratch.bodies[b].v, scalar.bodies[b].v, "v", i);
            expect_near(scratch.bodies[b].w, scalar.bodies[b].w, "w", i);
        }
    }
}

}  // namespace

TEST(JointLanes, BallSocketsPushAsTheScalarPointRowsInWarmStartSolveAndRelax) {
    std::mt19937 rng(7);
    constexpr int kBodies = 24;
    SolverScratch scratch;
    scratch.bodies = random_bodies(kBodies, rng);
    const auto immovable = static_cast<std::uint32_t>(kBodies);
    // Eleven joints on distinct bodies (one colour: two wide joints, the second with three
    // lanes), one of them to the immovable body, and one joint of a body with a
    // translation lock, which stays scalar.
    for (std::uint32_t k = 0; k < 11; ++k)
        scratch.joints.push_back(random_joint(2 * k, k == 4 ? immovable : 2 * k + 1, rng));
    scratch.bodies[22].locks = 0b001;
    scratch.joints.push_back(random_joint(22, 23, rng));
    for (std::uint32_t k = 0; k < scratch.joints.size(); ++k) scratch.joint_colors[0].push_back(k);

    pack_joint_lanes(scratch);
    ASSERT_EQ(scratch.wide_joints.size(), 2u);
    EXPECT_EQ(scratch.wide_joints[1].lanes, 3);
    ASSERT_EQ(scratch.joint_colors[0].size(), 1u);  // the locked body's joint
    EXPECT_EQ(scratch.joint_colors[0][0], 11u);
    const ScalarSide scalar = push_both_ways(scratch, 11, 2);
    expect_pushed_alike(scratch, scalar, 11);
    // The immovable body is shared by every colour: never written.
    EXPECT_EQ(scratch.bodies[immovable].v, Vec3::Zero());
    EXPECT_EQ(scratch.bodies[immovable].w, Vec3::Zero());
}

namespace {

Vec3 unit_vector(std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1, 1);
    Vec3 v;
    do v = Vec3(unit(rng), unit(rng), unit(rng));
    while (v.norm() < 0.1);
    return v.normalized();
}

Vec3 any_perpendicular(const Vec3& n) {
    const Vec3 t = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY();
    return (t - n * n.dot(t)).normalized();
}

// B turned from A by up to a radian about a random axis: swings and twists of either
// sign, some beyond the random cones and twist ranges, some within. Every fourth has no
// cone, every third no twist range, every other friction.
JointConstraint random_swing_twist(std::uint32_t a, std::uint32_t b, int k, const RawRoomVector<SolverBody>& bodies,
                                   std::mt19937& rng) {
    std::uniform_real_distribution<double> turn(0, 1), cone(0.2, 0.8), range(0.1, 0.6), impulse(0, 0.05);
    JointConstraint jc = random_joint(a, b, rng);
    jc.type = JointType::SwingTwist;
    const Quat rel(Eigen::AngleAxisd(turn(rng), unit_vector(rng)));
    jc.axis_a = unit_vector(rng);
    jc.ref_a = any_perpendicular(jc.axis_a);
    jc.axis_b = rel * jc.axis_a;
    jc.ref_b = rel * jc.ref_a;
    jc.cone = k % 4 == 0 ? kPi : cone(rng);
    const bool twist_range = k % 3 != 0;
    jc.lower = twist_range ? -range(rng) : -kPi;
    jc.upper = twist_range ? range(rng) : kPi;
    jc.swing_impulse = jc.cone < kPi ? impulse(rng) : 0;
    jc.lower_impulse = twist_range ? impulse(rng) : 0;
    jc.upper_impulse = twist_range ? impulse(rng) : 0;
    if (k % 2 == 0) {
        jc.max_friction_impulse = 0.03;
        jc.rotation_mass = Mat3(bodies[a].inv_inertia + bodies[b].inv_inertia).inverse();
        jc.angular_impulse = 0.01 * unit_vector(rng);
    }
    return jc;
}

// B's axis up to 0.15 rad off A's and turned about it by up to 1.5 rad either way; random
// limits (every fourth none, every third soft) and, every other one, a motor.
JointConstraint random_hinge(std::uint32_t a, std::uint32_t b, int k, std::mt19937& rng) {
    std::uniform_real_distribution<double> angle(-1.5, 1.5), tilt(0, 0.15), lower(-1, 0.5), width(0.1, 1),
        impulse(0, 0.05), speed(-3, 3);
    JointConstraint jc = random_joint(a, b, rng);
    jc.type = JointType::Hinge;
    jc.axis_a = unit_vector(rng);
    jc.ref_a = any_perpendicular(jc.axis_a);
    const Quat misalign(Eigen::AngleAxisd(tilt(rng), unit_vector(rng)));
    const Quat hinge(Eigen::AngleAxisd(angle(rng), jc.axis_a));
    const Vec3 axis_b = misalign * jc.axis_a;
    jc.perp_b[0] = misalign * (hinge * jc.ref_a);
    jc.perp_b[1] = axis_b.cross(jc.perp_b[0]);
    jc.ref_b = jc.perp_b[0];
    jc.align_impulse = Vec2(impulse(rng), -impulse(rng));
    jc.enable_limit = k % 4 != 0;
    jc.lower = lower(rng);
    jc.upper = jc.lower + width(rng);
    jc.soft_limit = jc.enable_limit && k % 3 == 0;
    jc.limit_spring = make_softness(jc.soft_limit ? 4.0 : 0.0, 0.7, 1.0 / 240);
    jc.lower_impulse = jc.enable_limit ? impulse(rng) : 0;
    jc.upper_impulse = jc.enable_limit ? impulse(rng) : 0;
    jc.enable_motor = k % 2 == 0;
    jc.motor_speed = speed(rng);
    jc.max_motor_impulse = 0.04;  // set without a motor too, as prepare_joint does
    jc.motor_impulse = jc.enable_motor ? impulse(rng) : 0;
    return jc;
}

}  // namespace

// Swing-twist joints and hinges, mixed with ball-sockets in one colour: one type to a
// block, and every row (friction, twist range, cone, motor, rigid and soft limits,
// alignment, the point) pushes as the scalar rows do, over warm start, solve and relax.
TEST(JointLanes, SwingTwistAndHingeRowsPushAsTheScalarRows) {
    std::mt19937 rng(11);
    constexpr int kBodies = 64;
    SolverScratch scratch;
    scratch.bodies = random_bodies(kBodies, rng);
    const auto immovable = static_cast<std::uint32_t>(kBodies);
    // 12 swing-twist joints, 12 hinges and 3 ball-sockets on distinct bodies, some to the
    // immovable body, interleaved as a colour's list is; then a swing-twist joint of a
    // body with a rotation lock, which stays scalar.
    std::uint32_t body = 0;
    auto pair = [&](int k) {
        const std::uint32_t a = body++;
        return std::pair<std::uint32_t, std::uint32_t>(a, k % 5 == 1 ? immovable : body++);
    };
    for (int k = 0; k < 27; ++k) {
        const auto [a, b] = pair(k);
        if (k % 9 == 8) {
            scratch.joints.push_back(random_joint(a, b, rng));
        } else if (k % 2 == 0) {
            scratch.joints.push_back(random_swing_twist(a, b, k / 2, scratch.bodies, rng));
        } else {
            scratch.joints.push_back(random_hinge(a, b, k / 2, rng));
        }
    }
    ASSERT_LT(body + 2, immovable);
    scratch.bodies[body].locks = 0b1000;
    scratch.joints.push_back(random_swing_twist(body, body + 1, 1, scratch.bodies, rng));
    const auto lane_joints = static_cast<std::uint32_t>(scratch.joints.size() - 1);
    for (std::uint32_t k = 0; k < scratch.joints.size(); ++k) scratch.joint_colors[0].push_back(k);

    pack_joint_lanes(scratch);
    ASSERT_EQ(scratch.joint_colors[0].size(), 1u);  // the locked body's joint
    EXPECT_EQ(scratch.joint_colors[0][0], lane_joints);
    int ball_sockets = 0, swing_twists = 0, hinges = 0;
    for (const WideJoint& wj : scratch.wide_joints) {
        for (int l = 0; l < wj.lanes; ++l) EXPECT_EQ(scratch.joints[wj.joint[l]].type, wj.type);
        (wj.type == JointType::SwingTwist ? swing_twists
         : wj.type == JointType::Hinge    ? hinges
                                          : ball_sockets) += wj.lanes;
    }
    EXPECT_EQ(ball_sockets, 3);
    EXPECT_EQ(swing_twists, 12);
    EXPECT_EQ(hinges, 12);
    EXPECT_EQ(scratch.wide_joints.size(), 1u + 2u + 2u);
    EXPECT_EQ(scratch.wide_swing_twists.size(), 2u);
    EXPECT_EQ(scratch.wide_hinges.size(), 2u);
    const auto blocks = static_cast<std::uint32_t>(scratch.wide_joints.size());
    const ScalarSide scalar = push_both_ways(scratch, lane_joints, blocks);
    expect_pushed_alike(scratch, scalar, lane_joints);
    // The limits and the motors were in play, not only the point rows.
    int pushing = 0;
    for (std::uint32_t k = 0; k < lane_joints; ++k) {
        const JointConstraint& jc = scalar.joints[k];
        pushing += (jc.swing_impulse > 1e-3) + (jc.lower_impulse > 1e-3) + (jc.upper_impulse > 1e-3);
    }
    EXPECT_GE(pushing, 8);
    EXPECT_EQ(scratch.bodies[immovable].v, Vec3::Zero());
    EXPECT_EQ(scratch.bodies[immovable].w, Vec3::Zero());
}

// The lanes' arctangent (joint_lanes.hpp) in every octant and on the axes, against the
// double one: within a few float roundings of the angle.
TEST(JointLanes, Atan2IsWithinFloatRoundingInEveryOctant) {
    double worst = 0;
    for (int i = 0; i < 4096; i += kLanes) {
        Wide y, x;
        for (int l = 0; l < kLanes; ++l) {
            const double angle = -kPi + 2 * kPi * (i + l) / 4096.0;
            const double radius = 0.25 + (i + l) % 7;
            y[l] = static_cast<float>(radius * std::sin(angle));
            x[l] = static_cast<float>(radius * std::cos(angle));
        }
        const Wide r = wide_atan2(y, x);
        for (int l = 0; l < kLanes; ++l) {
            double error = std::abs(r[l] - std::atan2(double(y[l]), double(x[l])));
            error = std::min(error, 2 * kPi - error);  // -pi and pi are one angle
            worst = std::max(worst, error);
        }
    }
    EXPECT_LT(worst, 1e-6);
    const Wide zero = splat(0), one = splat(1);
    EXPECT_EQ(wide_atan2(zero, zero)[0], 0.0f);
    EXPECT_NEAR(wide_atan2(one, zero)[0], kPi / 2, 1e-6);
    EXPECT_NEAR(wide_atan2(-one, zero)[0], -kPi / 2, 1e-6);
    EXPECT_NEAR(wide_atan2(zero, -one)[0], kPi, 1e-6);
}

// The lanes' square root (wide.hpp; the friction cone's and a wide joint's length): each
// lane the correctly rounded root, the same bits as the scalar one, over zeros, subnormals,
// the largest float, infinity and a spread of magnitudes, so the lanes' results never depend
// on which instruction a build has.
TEST(JointLanes, SquareRootIsEachLanesScalarRootToTheBit) {
    std::vector<float> values = {0.0f,
                                 -0.0f,
                                 std::numeric_limits<float>::denorm_min(),
                                 std::numeric_limits<float>::min(),
                                 std::numeric_limits<float>::max(),
                                 std::numeric_limits<float>::infinity(),
                                 1.0f,
                                 2.0f,
                                 3.0f};
    std::mt19937 random(19);
    std::uniform_real_distribution<float> exponent(-40.0f, 38.0f);
    while (values.size() % kLanes != 0 || values.size() < 4096) values.push_back(std::pow(10.0f, exponent(random)));
    int differing = 0;
    for (std::size_t i = 0; i < values.size(); i += kLanes) {
        Wide a;
        for (int l = 0; l < kLanes; ++l) a[l] = values[i + l];
        const Wide r = wide_sqrt(a);
        for (int l = 0; l < kLanes; ++l) {
            const float expected = std::sqrt(values[i + l]);
            std::uint32_t got_bits, expected_bits;
            std::memcpy(&got_bits, &r[l], sizeof(float));
            std::memcpy(&expected_bits, &expected, sizeof(float));
            if (got_bits != expected_bits) ++differing;
        }
    }
    EXPECT_EQ(differing, 0) << "of " << values.size() << " roots";
}

// The double lanes' max, min, |a| >= b and mask tests (wide.hpp; the contact solver's
// preparing clamps its friction weights and picks its tangent basis with them): each
// lane the scalar ternary's bits, NaN and signed zeros included, so a build with or
// without AVX gives what std::clamp and std::abs gave.
TEST(JointLanes, DoubleLanesMaxMinAndAbsAreTheScalarTernariesToTheBit) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double values[] = {0.0, -0.0, 1e-3, -1e-3, 1.0, -1.0, 0.57735, -0.57735, nan, 2.5, -7.0, 1e300};
    auto bits = [](double x) {
        std::uint64_t b;
        std::memcpy(&b, &x, sizeof b);
        return b;
    };
    int differing = 0;
    for (double x : values) {
        for (double y : values) {
            const WideD a = splat_d(x), b = splat_d(y);
            if (bits(wide_max(a, b)[3]) != bits(x > y ? x : y)) ++differing;
            if (bits(wide_min(a, b)[6]) != bits(x < y ? x : y)) ++differing;
            if ((abs_at_least(a, b)[5] != 0) != (std::abs(x) >= y)) ++differing;
        }
    }
    EXPECT_EQ(differing, 0);
    WideDMask mask{};
    EXPECT_FALSE(any(mask));
    mask[7] = -1;
    EXPECT_TRUE(any(mask));
    EXPECT_FALSE(all(mask));
    for (int l = 0; l < kLanes; ++l) mask[l] = -1;
    EXPECT_TRUE(all(mask));
    mask[0] = 0;
    EXPECT_FALSE(all(mask));
}

// Swing-twist joints swung nearly half a turn (150-178 degrees, where the arc that undoes
// the swing is short of an axis and the float lanes' twist rests on 1 + cos(swing)): the
// cone and twist rows still push as the scalar rows do.
TEST(JointLanes, SwingTwistNearlyHalfATurnPushesAsTheScalarRows) {
    std::mt19937 rng(23);
    constexpr int kBodies = 32;
    SolverScratch scratch;
    scratch.bodies = random_bodies(kBodies, rng);
    for (SolverBody& b : scratch.bodies) b.dq = Quat::Identity();  // the swing exactly as built
    std::uniform_real_distribution<double> swing(2.6, 3.1), twist(-1, 1), about(0, 2 * kPi);
    for (std::uint32_t k = 0; k < 16; ++k) {
        JointConstraint jc = random_swing_twist(2 * k, 2 * k + 1, static_cast<int>(k), scratch.bodies, rng);
        const Vec3 perp = Eigen::AngleAxisd(about(rng), jc.axis_a) * any_perpendicular(jc.axis_a);
        const Quat swung(Eigen::AngleAxisd(swing(rng), perp));
        const Quat rel = Quat(Eigen::AngleAxisd(twist(rng), swung * jc.axis_a)) * swung;
        jc.axis_b = rel * jc.axis_a;
        jc.ref_b = rel * jc.ref_a;
        scratch.joints.push_back(jc);
        scratch.joint_colors[0].push_back(k);
    }
    pack_joint_lanes(scratch);
    ASSERT_TRUE(scratch.joint_colors[0].empty());
    ASSERT_EQ(scratch.wide_swing_twists.size(), 2u);
    const auto blocks = static_cast<std::uint32_t>(scratch.wide_joints.size());
    const ScalarSide scalar = push_both_ways(scratch, 16, blocks);
    expect_pushed_alike(scratch, scalar, 16);
    int pushing = 0;
    for (const JointConstraint& jc : scalar.joints) pushing += (jc.swing_impulse > 1e-3);
    EXPECT_GE(pushing, 8);  // the cones (at most 46 degrees) are far exceeded: their rows push
}
