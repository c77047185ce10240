// Slerp by one fraction t for many quaternion pairs, without trigonometry (D. Eberly,
// "A Fast and Accurate Algorithm for Computing SLERP", 2011). A blended read turns every
// interpolating body by the same t, and libm's acos and three sines per body (Eigen's
// slerp) were most of the cost of reading 10k blended states. The slerp weights
// sin(t theta) / sin(theta) are a power series in cos(theta) - 1 whose coefficients
// depend on t alone, so they are made once per read and each body pays two polynomials.
// Published reads (api/motion_state_manager.cpp) and the query scene's poses blend with
// it alike, so a ray meets a body where its motion state puts it, to the bit.
#pragma once

#include <spindle/engine/math.hpp>

#include <array>

namespace spindle {

class SlerpSeries {
public:
    explicit SlerpSeries(Real t) : m_t(t) {
        fill(m_to_b, t);
        fill(m_to_a, 1 - t);
    }

    Real t() const noexcept { return m_t; }

    // slerp_shortest(a, b, t), equal to it within a few ulps (the series is cut where its
    // remainder is below double rounding: tests/engine/queries/slerp_series_test.cpp). Pairs
    // more than 1.44 rad apart (a body turning faster than 86 rad/s at 60 Hz) take the
    // exact slerp, where the series would need many more terms.
    Quat operator()(const Quat& a, const Quat& b) const {
        const Real d = a.dot(b);
        const Real sign = d < 0 ? -1 : 1;
        const Real x = sign * d - 1;  // cos(theta) - 1, in [-1, 0]
        if (x < kSeriesFrom) return slerp_shortest(a, b, m_t);
        Real wa = 0, wb = 0;
        // Each term is below |x| / 2 of the one before, so a step's small turn needs few.
        if (x >= -1.0 / 1024) {
            weights<4>(x, wa, wb);
        } else if (x >= -1.0 / 32) {
            weights<8>(x, wa, wb);
        } else {
            weights<kTerms>(x, wa, wb);
        }
        Quat q;
        q.coeffs() = wa * a.coeffs() + (sign * wb) * b.coeffs();
        return q;
    }

private:
    // With |cos(theta) - 1| <= 1/4 the sixteenth term is below 1e-16 of the sum; four
    // terms are enough up to 1/1024 (0.088 rad apart), eight up to 1/32 (0.5 rad).
    static constexpr int kTerms = 16;
    static constexpr Real kSeriesFrom = -0.25;

    // sin(s theta) / sin(theta) = sum over i of c_i(s) (cos(theta) - 1)^i, with c_0 = s and
    // c_i = c_(i-1) (s^2 - i^2) / (i (2 i + 1)).
    // Multiplied by 1 / (i (2 i + 1)) from a table: a blended pose of the query scene makes
    // its own series, so making one costs multiplications only.
    static void fill(std::array<Real, kTerms + 1>& c, Real s) {
        c[0] = s;
        for (int i = 1; i <= kTerms; ++i) c[i] = c[i - 1] * (s * s - static_cast<Real>(i * i)) * kInverse[i];
    }
    static constexpr std::array<Real, kTerms + 1> kInverse = [] {
        std::array<Real, kTerms + 1> r{};
        for (int i = 1; i <= kTerms; ++i) r[i] = 1.0 / static_cast<Real>(i * (2 * i + 1));
        return r;
    }();

    // The first `terms` + 1 terms of both weights, by Horner's rule.
    template <int terms>
    void weights(Real x, Real& wa, Real& wb) const {
        wa = m_to_a[terms];
        wb = m_to_b[terms];
        for (int i = terms - 1; i >= 0; --i) {
            wa = wa * x + m_to_a[i];
            wb = wb * x + m_to_b[i];
        }
    }

    std::array<Real, kTerms + 1> m_to_b{};  // the weight of b
    std::array<Real, kTerms + 1> m_to_a{};  // the weight of a
    Real m_t;
};

}  // namespace spindle
