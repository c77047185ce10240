// The blended reads' slerp without trigonometry (engine/src/query/slerp_series.hpp) gives
// what slerp_shortest gives, for every angle between two steps and every fraction.
#include <spindle/engine/math.hpp>

#include "query/slerp_series.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

namespace spindle {
namespace {

Quat random_rotation(std::mt19937_64& rng) {
    std::normal_distribution<Real> n;
    Quat q(n(rng), n(rng), n(rng), n(rng));
    return q.normalized();
}

// b turned from a by `angle` about a random axis, on either side of the 4D sphere.
Quat turned(const Quat& a, Real angle, std::mt19937_64& rng) {
    std::normal_distribution<Real> n;
    const Vec3 axis = Vec3(n(rng), n(rng), n(rng)).normalized();
    Quat b = a * Quat(Eigen::AngleAxis<Real>(angle, axis));
    if (rng() & 1) b.coeffs() = -b.coeffs();
    return b;
}

Real largest_difference(const Quat& p, const Quat& q) { return (p.coeffs() - q.coeffs()).cwiseAbs().maxCoeff(); }

// Rotations up to 1.44 rad apart take the series: it must match the exact slerp to a
// few ulps at the top of each range of angles that takes fewer terms (a series cut
// three terms early is off by 1e-14 to 1e-11 there).
TEST(SlerpSeries, MatchesSlerpForEveryAngleTheSeriesTakes) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<Real> fraction(0, 1), angle(0, 1.44);
    Real worst = 0;
    for (int k = 0; k < 2000; ++k) {
        const Real t = fraction(rng);
        const Quat a = random_rotation(rng);
        const Real tops[] = {1.44, 0.5, 0.088};  // where the series takes 16, 8 and 4 terms
        const Quat b = turned(a, k % 10 < 3 ? tops[k % 10] : angle(rng), rng);
        worst = std::max(worst, largest_difference(SlerpSeries(t)(a, b), slerp_shortest(a, b, t)));
    }
    EXPECT_LT(worst, 2e-15);
}

// Beyond the series' range the exact slerp answers, and whatever the angle the result is
// the rotation at the fraction t of the shortest arc, of unit length.
TEST(SlerpSeries, TurnsTheFractionOfTheShortestArcAtAnyAngle) {
    std::mt19937_64 rng(11);
    for (const Real angle : {0.0, 1e-9, 0.3, 1.0, 1.44, 1.5, 2.5, std::numbers::pi - 1e-6}) {
        for (const Real t : {0.0, 0.25, 0.5, 0.9, 1.0}) {
            const Quat a = random_rotation(rng);
            const Quat b = turned(a, angle, rng);
            const Quat q = SlerpSeries(t)(a, b);
            EXPECT_NEAR(q.norm(), 1.0, 1e-14) << "angle " << angle << " t " << t;
            EXPECT_NEAR(a.angularDistance(q), t * angle, 1e-9) << "angle " << angle << " t " << t;
            EXPECT_NEAR(q.angularDistance(b), (1 - t) * angle, 1e-9) << "angle " << angle << " t " << t;
        }
    }
}

}  // namespace
}  // namespace spindle
