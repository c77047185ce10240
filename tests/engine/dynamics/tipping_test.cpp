// A thin pole tipped over on its end: it must pivot down as a rigid rod does, not
// turn its tipping into a spin about its long axis (an elongated body keeps its
// angular momentum as it turns: BodyDesc::gyroscopic, kElongatedInertiaRatio).
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "static_bodies.hpp"

using namespace spindle;

namespace tipping_test {

namespace {

constexpr double kGravity = 9.81;

// A hexagonal prism along y, `length` long, its corners `radius` from the axis,
// centred on its origin.
Shape hexagonal_prism(Real length, Real radius) {
    std::array<Vec3, 12> points;
    for (int k = 0; k < 6; ++k) {
        const Real a = k * kPi / 3;
        points[2 * k] = Vec3(radius * std::cos(a), -length / 2, radius * std::sin(a));
        points[2 * k + 1] = Vec3(radius * std::cos(a), length / 2, radius * std::sin(a));
    }
    return Shape::convex_hull(points);
}

// The time a rigid rod of this length takes to pivot on its end from upright, starting
// at spin w0, down to lying flat: the integral of dtheta / sqrt(w0^2 + (3g/L)(1 - cos theta)).
double rod_pivot_time(double length, double w0) {
    const int n = 100000;
    const double k = 3 * kGravity / length;
    double t = 0;
    for (int i = 0; i < n; ++i) {
        const double theta = (i + 0.5) * (kPi / 2) / n;
        t += (kPi / 2 / n) / std::sqrt(w0 * w0 + k * (1 - std::cos(theta)));
    }
    return t;
}

}  // namespace

// A 30 m x 0.3 m pole (principal inertias 2000 : 1) standing on its end on a plane,
// tipped at 0.25 rad/s with 0.002 rad/s out of the tipping plane. Without the
// gyroscopic turn, that small spin grows into one about the pole's own axis (tens of
// rad/s) and the pole stalls on its way down.
TEST(Tipping, ThinPoleFallsInItsPivotTimeWithoutSpinningAboutItsAxis) {
    Space space;
    BodyDesc ground = test::ground_plane();
    ground.friction = 0.9;
    space.create_body(ground);

    const Real length = 30, w0 = 0.25;
    BodyDesc d;
    d.shape = hexagonal_prism(length, 0.3);
    d.position = Vec3(0, length / 2, 0);
    d.friction = 0.9;
    d.angular_velocity = Vec3(0.002, 0, w0);
    d.linear_velocity = d.angular_velocity.cross(Vec3(0, length / 2, 0));  // pivoting on its base
    const BodyHandle pole = space.create_body(d);

    const double dt = space.settings().time_step.duration;
    const double expected = rod_pivot_time(length, w0);  // 3.18 s
    const double lying = 88 * kPi / 180;
    const double high = 75 * kPi / 180;
    double down_at = -1, largest_axial = 0;
    for (int step = 1; step <= 600 && down_at < 0; ++step) {
        space.update();
        const Vec3 axis = space.internal_orientation(pole) * Vec3::UnitY();
        const double tilt = std::acos(std::clamp(std::abs(axis.y()), 0.0, 1.0));
        if (tilt < high) {
            largest_axial = std::max(largest_axial, std::abs(space.internal_angular_velocity(pole).dot(axis)));
        }
        if (tilt >= lying) down_at = step * dt;
    }
    std::printf(
        "pole lies down at %.3f s (rod: %.3f s); largest spin about its axis before 75 degrees of tilt: %.3f rad/s\n",
        down_at, expected, largest_axial);
    ASSERT_GT(down_at, 0) << "the pole never came down";
    EXPECT_NEAR(down_at, expected, 0.1 * expected);
    // Until it has tipped 75 degrees, no faster about its axis than the rod's own rate
    // when it lands: sqrt(w0^2 + 3g/L), 1.02 rad/s.
    EXPECT_LT(largest_axial, 1.03);
}

}  // namespace tipping_test
