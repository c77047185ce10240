// Ball-socket joints solved eight at a time in floats (joint_ball_socket.cpp) push their
// bodies as the scalar point rows in doubles do (joint_solver.cpp's solve_point), lane for
// lane, empty lanes and all; joints of a locked body stay with the scalar rows.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "solver/constraints.hpp"

using namespace spindle;

namespace {

// Random bodies: turned, moving and already moved, with uneven inertias (a general
// symmetric inverse inertia in world), masses over two decades. The last is the
// immovable partner of static bodies, as in a step.
std::vector<SolverBody> random_bodies(int count, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1, 1), mass(0.5, 50);
    auto vec = [&] { return Vec3(unit(rng), unit(rng), unit(rng)); };
    std::vector<SolverBody> bodies(static_cast<std::size_t>(count) + 1);
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

}  // namespace

TEST(BallSocketLanes, PushAsTheScalarPointRowsInWarmStartSolveAndRelax) {
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

    pack_ball_sockets(scratch);
    ASSERT_EQ(scratch.wide_joints.size(), 2u);
    EXPECT_EQ(scratch.wide_joints[1].lanes, 3);
    ASSERT_EQ(scratch.joint_colors[0].size(), 1u);  // the locked body's joint
    EXPECT_EQ(scratch.joint_colors[0][0], 11u);
    prepare_ball_sockets(scratch, 0, 2);

    std::vector<SolverBody> scalar_bodies = scratch.bodies;
    std::vector<JointConstraint> scalar_joints = scratch.joints;
    const JointSolveParams solve{make_softness(60, 2, 1.0 / 240), 240, true};
    const JointSolveParams relax{solve.soft, solve.inv_h, false};
    EffectCounts wide_counts, scalar_counts;
    for (std::uint32_t k = 0; k < 11; ++k) warm_start_joint(scalar_joints[k], scalar_bodies.data());
    for (WideBallSocket& wj : scratch.wide_joints) warm_start_ball_sockets(wj, scratch.bodies.data());
    for (const JointSolveParams& params : {solve, relax, solve}) {
        for (std::uint32_t k = 0; k < 11; ++k)
            solve_joint(scalar_joints[k], scalar_bodies.data(), params, scalar_counts);
        for (WideBallSocket& wj : scratch.wide_joints)
            solve_ball_sockets(wj, scratch.bodies.data(), params, wide_counts);
    }
    store_ball_socket_impulses(scratch, 0, 2);
    EXPECT_EQ(wide_counts.joints, scalar_counts.joints);
    for (int k = 0; k < 11; ++k) {
        const auto i = static_cast<std::size_t>(k);
        expect_near(scratch.joints[i].linear_impulse, scalar_joints[i].linear_impulse, "impulse", k);
        for (const std::uint32_t body : {scratch.joints[i].a, scratch.joints[i].b}) {
            expect_near(scratch.bodies[body].v, scalar_bodies[body].v, "v", k);
            expect_near(scratch.bodies[body].w, scalar_bodies[body].w, "w", k);
        }
    }
    // The immovable body is shared by every colour: never written.
    EXPECT_EQ(scratch.bodies[immovable].v, Vec3::Zero());
    EXPECT_EQ(scratch.bodies[immovable].w, Vec3::Zero());
}
