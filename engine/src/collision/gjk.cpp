// GJK on point sets: the simplex is reduced with Ericson's closest-point region tests
// (Real-Time Collision Detection, 5.1.5), which stay well behaved in double precision.
#include "collision/gjk.hpp"

#include <cmath>

namespace spindle::detail {
namespace {

struct SimplexVertex {
    Vec3 a;  // support point of a
    Vec3 b;  // support point of b
    Vec3 w;  // a - b
};

struct Simplex {
    SimplexVertex v[4];
    Real weight[4] = {1, 0, 0, 0};
    int count = 0;

    Vec3 closest() const {
        Vec3 p = Vec3::Zero();
        for (int i = 0; i < count; ++i) p += weight[i] * v[i].w;
        return p;
    }
    void keep(std::initializer_list<int> indices, std::initializer_list<Real> weights) {
        SimplexVertex kept[4];
        int n = 0;
        for (int i : indices) kept[n++] = v[i];
        n = 0;
        for (Real w : weights) weight[n++] = w;
        for (int i = 0; i < n; ++i) v[i] = kept[i];
        count = n;
    }
};

int support(const Vec3* p, int count, const Vec3& d) {
    int best = 0;
    Real best_dot = p[0].dot(d);
    for (int i = 1; i < count; ++i) {
        const Real x = p[i].dot(d);
        if (x > best_dot) best_dot = x, best = i;
    }
    return best;
}

void solve_segment(Simplex& s) {
    const Vec3& a = s.v[0].w;
    const Vec3 ab = s.v[1].w - a;
    const Real t = -a.dot(ab);
    if (t <= 0) return s.keep({0}, {1});
    const Real len2 = ab.squaredNorm();
    if (t >= len2) return s.keep({1}, {1});
    const Real u = t / len2;
    s.keep({0, 1}, {1 - u, u});
}

// Reduces triangle (i, j, k) of the simplex to the feature closest to the origin.
void solve_triangle(Simplex& s, int i, int j, int k) {
    const Vec3& a = s.v[i].w;
    const Vec3& b = s.v[j].w;
    const Vec3& c = s.v[k].w;
    const Vec3 ab = b - a, ac = c - a;
    const Vec3 ap = -a;
    const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return s.keep({i}, {1});
    const Vec3 bp = -b;
    const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return s.keep({j}, {1});
    const Real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const Real t = d1 / (d1 - d3);
        return s.keep({i, j}, {1 - t, t});
    }
    const Vec3 cp = -c;
    const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return s.keep({k}, {1});
    const Real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const Real t = d2 / (d2 - d6);
        return s.keep({i, k}, {1 - t, t});
    }
    const Real va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        const Real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return s.keep({j, k}, {1 - t, t});
    }
    const Real sum = va + vb + vc;
    if (!(sum > 0)) return s.keep({i}, {1});  // flat triangle: vertex regions cover it
    const Real v = vb / sum, w = vc / sum;
    s.keep({i, j, k}, {1 - v - w, v, w});
}

// Returns false when the origin is inside the tetrahedron.
bool solve_tetrahedron(Simplex& s) {
    static constexpr int kFaces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
    Simplex best;
    Real best_d2 = kHuge;
    bool outside_any = false;
    for (const auto& f : kFaces) {
        const Vec3& a = s.v[f[0]].w;
        const Vec3 n = (s.v[f[1]].w - a).cross(s.v[f[2]].w - a);
        // Origin and the opposite vertex on different sides (or a flat tetrahedron).
        if ((-a).dot(n) * (s.v[f[3]].w - a).dot(n) > 0) continue;
        outside_any = true;
        Simplex t = s;
        solve_triangle(t, f[0], f[1], f[2]);
        const Real d2 = t.closest().squaredNorm();
        if (d2 < best_d2) best_d2 = d2, best = t;
    }
    if (!outside_any) return false;
    s = best;
    return true;
}

}  // namespace

GjkResult gjk_distance(const Vec3* a, int a_count, const Vec3* b, int b_count) {
    constexpr int kMaxIterations = 64;
    constexpr Real kOverlap2 = 1e-24;
    Simplex s;
    s.v[0] = {a[0], b[0], a[0] - b[0]};
    s.count = 1;
    Vec3 v = s.v[0].w;
    Real d2 = v.squaredNorm();
    GjkResult result;
    for (int iteration = 0; iteration < kMaxIterations && d2 > kOverlap2; ++iteration) {
        const int ia = support(a, a_count, -v);
        const int ib = support(b, b_count, v);
        const Vec3 w = a[ia] - b[ib];
        // No support point gets meaningfully closer than v: v is the closest point.
        if (d2 - v.dot(w) <= Real(1e-12) * d2) break;
        bool repeated = false;
        for (int i = 0; i < s.count; ++i) repeated = repeated || s.v[i].w == w;
        if (repeated) break;
        const Simplex previous = s;
        s.v[s.count++] = {a[ia], b[ib], w};
        bool inside = false;
        switch (s.count) {
            case 2: solve_segment(s); break;
            case 3: solve_triangle(s, 0, 1, 2); break;
            default: inside = !solve_tetrahedron(s); break;
        }
        if (inside) {
            result.overlap = true;
            return result;
        }
        const Vec3 next = s.closest();
        const Real next_d2 = next.squaredNorm();
        if (next_d2 >= d2) {
            s = previous;  // round-off: keep the last simplex that made progress
            break;
        }
        v = next;
        d2 = next_d2;
    }
    if (d2 <= kOverlap2) {
        result.overlap = true;
        return result;
    }
    for (int i = 0; i < s.count; ++i) {
        result.point_a += s.weight[i] * s.v[i].a;
        result.point_b += s.weight[i] * s.v[i].b;
    }
    result.distance = std::sqrt(d2);
    return result;
}

}  // namespace spindle::detail
