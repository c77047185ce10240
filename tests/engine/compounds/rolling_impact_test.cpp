// A tree as trees100's (22 hexagonal prism parts, tapering) lying on its side and rolled
// down a gentle slope: each time a face lands it pivots on an edge and the landing takes
// most of its roll (an impact about the new edge keeps 11/17 of the spin of one prism),
// so it stops after a few faces, as many on a flat triangle mesh as on a plane and the
// same rolling either way. Box3D's tree does the same on both. Before the narrowphase put
// a landing manifold's points fastest approaching first, the solver took them in the
// collide's order: the mesh's merge listed the edge a tree pivots on before the landing
// edge, the plane its face's vertices (the landing edge first rolling one way, the pivot
// the other), and with the pivot taken first it kept pushing through the landing and the
// tree rolled a face further.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include "grid_mesh.hpp"

namespace spindle {
namespace rolling_impact {
namespace {

constexpr Real kSlope = 0.1;

// A six-sided prism of radius r along y, from y0 to y0 + height (Box3D's b3CreateCylinder).
Shape hexagonal_prism(Real r, Real y0, Real height) {
    std::vector<Vec3> points;
    for (int k = 0; k < 6; ++k) {
        const Real a = k * std::numbers::pi / 3;
        for (Real y : {y0, y0 + height}) points.emplace_back(r * std::cos(a), y, r * std::sin(a));
    }
    return Shape::convex_hull(points);
}

// trees.toml's tree: 22 prisms, each 1.5 m plus two radii tall, the radius 0.75 shrinking
// by 0.95 a part.
Shape tree() {
    std::vector<CompoundPart> parts;
    Real y = 1, r = 0.75;
    for (int i = 0; i < 22; ++i) {
        parts.push_back({hexagonal_prism(r, y - r, 1.5 + 2 * r)});
        y += 1.5 + 2 * r;
        r *= 0.95;
    }
    return Shape::compound(parts);
}

// A space with trees100's sleep threshold and gravity `gravity`, on level ground (a plane,
// or a flat mesh of `cells` 1 m cells a side), and trees100's tree at `position`, turned
// by `orientation`.
struct TreeOnGround {
    Space space;
    BodyHandle log;

    TreeOnGround(const Vec3& gravity, bool mesh, int cells, const Vec3& position, const Quat& orientation)
        : space(settings(gravity)) {
        BodyDesc ground;
        ground.type = MotionType::Static;
        ground.shape = mesh ? test::flat_grid_mesh(cells, 1) : Shape::plane(Vec3(0, 1, 0), 0);
        space.create_body(ground);
        BodyDesc desc;
        desc.shape = tree();
        desc.density = 1;
        desc.friction = 0.9;
        desc.rolling_resistance = 0.05;
        desc.position = position;
        desc.orientation = orientation;
        log = space.create_body(desc);
    }

    static SpaceSettings settings(const Vec3& gravity) {
        SpaceSettings s;
        s.gravity = gravity;
        s.sleep.linear_threshold = 0.2;  // trees100's
        return s;
    }
};

// How far (m, down the slope) the tree lying along z rolls before it sleeps, set rolling
// down the slope at `spin` rad/s about its first part's bottom edge. The slope is gravity
// tilted along x over level ground, down toward +x (`way` 1) or -x (-1): a manifold lists
// its points in the same order either way, so one of the two rolls lands on the points
// listed last.
Real roll(bool mesh, Real spin, Real way) {
    const Real tilt = std::atan(kSlope);
    const Real inner = 0.75 * std::sqrt(Real(3)) / 2;  // the first part's face from its axis
    TreeOnGround scene(Vec3(way * 10 * std::sin(tilt), -10 * std::cos(tilt), 0), mesh, 120,
                       Vec3(-5 * way, inner + 0.001, -1.75),
                       Quat(Eigen::AngleAxis<Real>(std::numbers::pi / 2, Vec3::UnitX())));
    Space& space = scene.space;
    const BodyHandle log = scene.log;
    for (int step = 0; step < 30; ++step) space.update();  // settle on a face
    MotionState state = space.internal_motion_state(log);
    state.angular_velocity = Vec3(0, 0, -way * spin);  // rolls down the slope
    state.linear_velocity = Vec3(way * spin * inner, 0, 0);
    space.set_internal_motion_state(log, state);
    const Real start = state.center_of_mass.x();
    for (int step = 0; step < 600 && space.internal_is_awake(log); ++step) space.update();
    EXPECT_FALSE(space.internal_is_awake(log))
        << (mesh ? "mesh" : "plane") << ", spin " << spin << ", way " << way << ": still rolling";
    return way * (space.internal_motion_state(log).center_of_mass.x() - start);
}

// The spins sampled run from one face to five. Each number of faces holds over a band of
// spins, and where two bands meet a landing's last millimetre decides between them, so a
// spin sampled there may roll one face more one way than the other whatever the engine;
// the bands move with any change to the solver. So the spins sit inside the bands (each
// 0.2 rad/s or more from an edge when this was written), two or more a band, and the
// property is asked over the sweep: at most one sampled spin may disagree by a face. A tree that rolls further on the
// mesh, or one way, does so over half of each band (the manifold's points in the collide's order disagreed at six of
// these eight spins).
TEST(RollingImpact, ATreeRolledDownASlopeStopsAfterAsManyFacesOnAFlatMeshAsOnAPlaneEitherWay) {
    const Real face = 0.75;  // the first part's side: how far one face's roll takes it
    int disagree = 0;
    std::string differing;
    Real last = 0;
    for (const Real spin : {1.85, 2.5, 2.8, 3.6, 3.9, 4.5, 4.65, 5.35}) {
        const Real rolls[] = {roll(false, spin, 1), roll(false, spin, -1), roll(true, spin, 1), roll(true, spin, -1)};
        const auto [least, most] = std::minmax_element(std::begin(rolls), std::end(rolls));
        EXPECT_GT(*least, 0.5 * face) << "spin " << spin << ": never rolled over a face";
        EXPECT_GE(rolls[0], last - 0.4 * face) << "spin " << spin << ": a faster spin rolled less far";
        last = rolls[0];
        if (*most - *least > 0.4 * face) {
            ++disagree;
            differing += "spin " + std::to_string(spin) + ": plane " + std::to_string(rolls[0]) + " / " +
                         std::to_string(rolls[1]) + ", mesh " + std::to_string(rolls[2]) + " / " +
                         std::to_string(rolls[3]) + " m (down +x / -x); ";
        }
    }
    EXPECT_LE(disagree, 1) << "the plane and the mesh, one way and the other, differ by a face at " << differing;
}

// How high (m) the tree's centre of mass rises again, once it is lying, above the lowest
// it had come down to, when it is stood on its base and tipped over at `spin` rad/s (as
// trees100 sets its trees going) onto a plane or a flat mesh.
Real bounce(bool mesh, Real spin) {
    const Vec3 base(0, 1, 0);
    TreeOnGround scene(Vec3(0, -10, 0), mesh, 150, base, Quat::Identity());
    Space& space = scene.space;
    const BodyHandle log = scene.log;
    MotionState state = space.internal_motion_state(log);
    state.angular_velocity = Vec3(0, 0, -spin);
    state.linear_velocity = state.angular_velocity.cross(state.center_of_mass - base);
    space.set_internal_motion_state(log, state);
    bool lying = false;
    Real lowest = kHuge, rise = 0;  // the most it rose above where it had come down to
    for (int step = 0; step < 900 && space.internal_is_awake(log); ++step) {
        space.update();
        const MotionState now = space.internal_motion_state(log);
        lying = lying || (now.orientation * Vec3::UnitY()).y() < 0.1;
        if (!lying) continue;
        lowest = std::min(lowest, now.center_of_mass.y());
        rise = std::max(rise, now.center_of_mass.y() - lowest);
    }
    EXPECT_TRUE(lying && !space.internal_is_awake(log))
        << (mesh ? "mesh" : "plane") << ", spin " << spin << ": never lay down and slept";
    return rise;
}

// A tree tipped over lands along its length within a step or two: its far end, turning
// fastest, comes down several times faster than its centre. Each part comes into reach
// by its own speed (the body's turn counted), so the whole length lands together and the
// tree stops where it lies, as Box3D's does (its centre rises 0.3 m). When only the parts
// near the base came into reach (the reach was the centres' speed), the landing stopped
// them alone and the tree pivoted there: its base and centre flew up 2 to 7 m.
TEST(RollingImpact, ATreeTippedOverLandsWithoutBouncingUp) {
    for (const bool mesh : {false, true}) {
        for (const Real spin : {0.1, 0.25, 0.5}) {
            EXPECT_LT(bounce(mesh, spin), 1.0) << (mesh ? "mesh" : "plane") << ", spin " << spin;
        }
    }
}

}  // namespace
}  // namespace rolling_impact
}  // namespace spindle
