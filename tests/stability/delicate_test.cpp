// Delicate structures at the default settings (issue 16): a house of cards and an arch
// of voussoirs, built exactly touching, must stand. Each test names what issue 16
// measured before.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "scene_util.hpp"

namespace spindle::stability {

namespace {

// A playing card: 88 x 63 mm, 2 mm thick, of card (700 kg/m^3), friction 0.5.
const Vec3 kCard(0.044, 0.001, 0.0315);
constexpr double kCardDensity = 700;
constexpr double kCardFriction = 0.5;
constexpr double kLean = 68 * kPi / 180;  // a leaning card's angle from horizontal
constexpr double kGap = 1e-4;             // each card is built this far above what it rests on

// Uniform in [-1, 1), the same on every platform (splitmix64): the jittered houses must be
// the same houses everywhere.
class Jitter {
public:
    explicit Jitter(std::uint64_t seed) : m_state(seed) {}
    double operator()() {
        std::uint64_t z = (m_state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        z ^= z >> 31;
        return static_cast<double>(z >> 11) * 0x1.0p-52 - 1;
    }

private:
    std::uint64_t m_state;
};

BodyHandle add_card(Space& space, const Vec3& position, double angle_about_z) {
    BodyDesc d;
    d.shape = Shape::box(kCard);
    d.position = position;
    d.orientation = Quat(Eigen::AngleAxis<Real>(angle_about_z, Vec3::UnitZ()));
    d.density = kCardDensity;
    d.friction = kCardFriction;
    return space.create_body(d);
}

// The highest point of a box of these half extents.
double top_of(const Space& space, BodyHandle body, const Vec3& half_extents) {
    const Mat3 r = space.internal_orientation(body).toRotationMatrix();
    return space.internal_position(body).y() + r.row(1).cwiseAbs().dot(half_extents);
}

struct CardHouse {
    std::vector<BodyHandle> cards;
    std::array<BodyHandle, 2> top{};  // the top pair
};

// Level k (0 at the bottom) has 5 - k leaning pairs whose apexes are one card length
// (plus a gap) apart, and a flat card lies across each two neighbouring apexes, end to
// end with the next, as the floor of level k + 1, whose pairs stand on the flat cards'
// middles. The cards of a pair touch along their inner top edges at the apex; each
// leaning card's top edge lies 2 b sin(lean) (1.9 mm) inside the apex, so a flat card's
// end overhangs the edge it rests on by that much.
// off > 0: each card is built up to off along x from its place, at random (seed).
CardHouse build_card_house(Space& space, int levels, double off = 0, std::uint64_t seed = 0) {
    Jitter jitter(seed);
    auto shift = [&] { return off > 0 ? Vec3(off * jitter(), 0, 0) : Vec3::Zero(); };
    add_static_box(space, Vec3(1, 0.5, 1), Vec3(0, -0.5, 0), Quat::Identity(), kCardFriction);
    const double a = kCard.x(), b = kCard.y();
    const double c = std::cos(kLean), s = std::sin(kLean);
    const double spacing = 2 * a + kGap;               // apex to apex
    const double pair_height = 2 * a * s + 2 * b * c;  // floor to the leaning cards' top edges
    CardHouse house;
    double floor_y = 0;
    for (int level = 0; level < levels; ++level) {
        const int pairs = levels - level;
        const double centre_y = floor_y + kGap + a * s + b * c;
        for (int j = 0; j < pairs; ++j) {
            const double apex = (j - 0.5 * (pairs - 1)) * spacing;
            const double half = a * c + b * s;  // apex to a leaning card's centre, in x
            const BodyHandle left = add_card(space, Vec3(apex - half, centre_y, 0) + shift(), kLean);
            const BodyHandle right = add_card(space, Vec3(apex + half, centre_y, 0) + shift(), -kLean);
            house.cards.push_back(left);
            house.cards.push_back(right);
            house.top = {left, right};
        }
        const double flat_y = floor_y + kGap + pair_height + kGap + b;
        for (int j = 0; j + 1 < pairs; ++j) {
            const double apex = (j - 0.5 * (pairs - 1)) * spacing;
            house.cards.push_back(add_card(space, Vec3(apex + 0.5 * spacing, flat_y, 0) + shift(), 0));
        }
        floor_y = flat_y + b;
    }
    return house;
}

double house_top(const Space& space, const CardHouse& house) {
    return std::max(top_of(space, house.top[0], kCard), top_of(space, house.top[1], kCard));
}

// The angle a card has turned about z (the house's plane) from the orientation it was built with.
double turned(const Space& space, BodyHandle card, const Quat& built) {
    return Eigen::AngleAxis<Real>(built.conjugate() * space.internal_orientation(card)).angle();
}

// How far the top pair has racked: the more its two cards have turned, in radians.
double top_racking(const Space& space, const CardHouse& house, const std::array<Quat, 2>& built) {
    return std::max(turned(space, house.top[0], built[0]), turned(space, house.top[1], built[1]));
}

// A semicircular arch of voussoirs on a floor whose top is at y = 0: stone i is the hull
// of the trapezoid between radii inner and outer over angles i pi / n to (i + 1) pi / n,
// depth deep along z, its origin at the middle of that trapezoid (radius and angle). The
// stones touch along their radial faces; the two springers are built kGap above the floor.
struct Arch {
    int stones = 11;
    double inner = 2, outer = 2.5;  // radii, m
};
constexpr double kDeep = 1;
constexpr double kStoneDensity = 2500;
constexpr double kStoneFriction = 0.6;

std::vector<BodyHandle> build_arch(Space& space, const Arch& arch) {
    add_static_box(space, Vec3(5, 0.5, 2), Vec3(0, -0.5, 0), Quat::Identity(), kStoneFriction);
    std::vector<BodyHandle> stones;
    for (int i = 0; i < arch.stones; ++i) {
        const double from = i * kPi / arch.stones, to = (i + 1) * kPi / arch.stones, mid = 0.5 * (from + to);
        const double r_mid = 0.5 * (arch.inner + arch.outer);
        const Vec3 origin(r_mid * std::cos(mid), r_mid * std::sin(mid), 0);
        std::vector<Vec3> points;
        for (double r : {arch.inner, arch.outer}) {
            for (double angle : {from, to}) {
                for (double z : {-0.5 * kDeep, 0.5 * kDeep}) {
                    points.push_back(Vec3(r * std::cos(angle), r * std::sin(angle), z) - origin);
                }
            }
        }
        BodyDesc d;
        d.shape = Shape::convex_hull(points);
        d.position = origin + Vec3(0, kGap, 0);
        d.density = kStoneDensity;
        d.friction = kStoneFriction;
        stones.push_back(space.create_body(d));
    }
    return stones;
}

}  // namespace

// A 5-level house of cards (issue 16: "At the defaults, a 5-level card house ...
// collapse[s]"): 15 leaning pairs at 68 degrees and 10 flat cards, 40 cards of 7.8 g,
// built exactly as above on a static floor, sleeping off, at the default settings. A
// house that stands keeps its top within a card's width or so of where it was built (a
// falling one drops tens of cm), its top pair upright (a toppled pair turns by tens of
// degrees or more), each card stays where it settled in the first second, and it comes
// to rest. Measured at 8dd705a: the top drops 11.5 mm in the first second, the flat cards
// sinking 1.5 to 2 mm into the edges under them: the soft contacts' compression (load
// over effective mass over (2 pi 30 Hz)^2; 4.8 mm at 8 substeps, 2.4 mm at 16, so one
// over the stiffness squared), not the 5 mm linear slop, which no normal row reads.
// The top pair racks 9.8 degrees as it lands (4.5 at 8 substeps; 1.1 with 4 iterations
// and 4 relax iterations): its apex contact takes one card's face normal, 22 degrees off
// the symmetric push, so friction there carries 0.40 of the push against a 0.5 cone, and
// with no warm start yet it slides; then it rests (1.9 mm more in 9 s, 2e-4 m/s at the
// end). It is marginal: built with each card up to 0.5 mm off, 5 houses in 19 lose their
// top pair (none at 8 substeps). Box3D (30c67b5, the same house at its defaults, also
// 30 Hz) loses its top pair: it topples (turned over, the top 94 mm down); at 8
// substeps it drops 12.6 mm (docs/accuracy.md, "Delicate structures"). The 1 cm drop
// bound chosen before measuring failed; 2 cm and 20 degrees guard the fall, the
// sag and racking stay a known cost of 30 Hz contacts. On main when the issue was filed
// (2321258, this test built there) the house fell: its top 406 mm down. The racking
// bound fails where the top pair topples: with contact_hertz 60 at 4 substeps (171
// degrees), with the friction cones cut to 0.4 of Coulomb's (70 degrees, the top 413 mm
// down).
// With the wedge normal at the apex (collide_box.cpp): 13.2 mm down, racked 2.7 degrees.
TEST(Delicate, CardHouseOfFiveLevelsStands) {
    auto space = make_space();  // sleep off: any creep shows
    const CardHouse house = build_card_house(*space, 5);
    ASSERT_EQ(house.cards.size(), 40u);
    const double built_top = house_top(*space, house);
    const std::array<Quat, 2> built_top_pair{space->internal_orientation(house.top[0]),
                                             space->internal_orientation(house.top[1])};
    double worst_drop = 0, worst_racking = 0;
    for (int step = 0; step < 60; ++step) {  // 1 s to settle
        space->update();
        worst_drop = std::max(worst_drop, built_top - house_top(*space, house));
        worst_racking = std::max(worst_racking, top_racking(*space, house, built_top_pair));
    }
    const std::vector<Vec3> settled = positions(*space, house.cards);
    double worst = 0;
    for (int step = 0; step < 540; ++step) {
        space->update();
        worst_drop = std::max(worst_drop, built_top - house_top(*space, house));
        worst_racking = std::max(worst_racking, top_racking(*space, house, built_top_pair));
        worst = std::max(worst, max_displacement(*space, house.cards, settled));
    }
    const double end_drop = built_top - house_top(*space, house);
    const double speed = max_speed(*space, house.cards);
    std::printf(
        "[ measure  ] card house 5 levels: top built at %.4f m, dropped %.2f mm at worst, %.2f mm at the end; top "
        "pair racked %.2f degrees at worst; worst card moved %.3f mm from its pose at 1 s in 9 s; fastest at the "
        "end %.2g m/s\n",
        built_top, 1000 * worst_drop, 1000 * end_drop, worst_racking * 180 / kPi, 1000 * worst, speed);
    EXPECT_TRUE(all_finite(*space, house.cards));
    EXPECT_LT(worst_drop, 0.02);
    EXPECT_LT(worst_racking, 20 * kPi / 180);
    EXPECT_LT(worst, 0.003);
    EXPECT_LT(speed, 0.001);
}

// The same house built with each card up to 0.5 mm off along x (at random, 19 houses):
// a house that stands only when built exactly is marginal. Each must keep its top pair:
// its top less than 2 cm down and the pair racked less than 20 degrees, at worst over
// 5 s (a pair that topples turns by tens of degrees and drops its top 94 mm). Main at
// 23820ad failed it: 3 of these 19 houses (seeds 1, 10 and 15) lost their top pair
// (racked 176-179 degrees, top 94-95 mm down), the apex contact taking one card's face
// normal, 22 degrees off the symmetric push; none fell at 8 substeps, with 4 iterations
// and 4 relax iterations, or at friction 0.7, and a position pass after each substep
// (Box2D v2.4's, Jolt's) made all 19 fall (docs/accuracy.md, "Delicate structures"). With
// the wedge normal (collide_box.cpp) all 19 stand: top 11.9-15.0 mm down, racked
// 1.2-9.8 degrees (median 2.1). Caught: the wedge normal left out (seeds 1, 10 and 15
// fall), its band 0.4 times as wide (seeds 1 and 10 fall) or 16 times (all 19 fall).
TEST(Delicate, CardHousesBuiltSlightlyOffKeepTheirTopPair) {
    constexpr double kOff = 0.0005;
    int fallen = 0;
    for (std::uint64_t seed = 1; seed <= 19; ++seed) {
        auto space = make_space();
        const CardHouse house = build_card_house(*space, 5, kOff, seed);
        const double built_top = house_top(*space, house);
        const std::array<Quat, 2> built{space->internal_orientation(house.top[0]),
                                        space->internal_orientation(house.top[1])};
        double worst_drop = 0, worst_racking = 0;
        for (int step = 0; step < 300; ++step) {
            space->update();
            worst_drop = std::max(worst_drop, built_top - house_top(*space, house));
            worst_racking = std::max(worst_racking, top_racking(*space, house, built));
        }
        const bool stands = all_finite(*space, house.cards) && worst_drop < 0.02 && worst_racking < 20 * kPi / 180;
        fallen += stands ? 0 : 1;
        std::printf("[ measure  ] card house, seed %2d: top dropped %.2f mm at worst, top pair racked %.2f degrees%s\n",
                    static_cast<int>(seed), 1000 * worst_drop, worst_racking * 180 / kPi, stands ? "" : ": fell");
    }
    EXPECT_EQ(fallen, 0);
}

// A semicircular arch of 11 voussoirs (inner radius 2 m, outer 2.5 m, 1 m deep; about
// 800 kg each, friction 0.6) on a static floor, sleeping off, at the default settings.
// Issue 16: an arch of voussoirs collapses at the defaults. It is twice as thick as the
// thinnest semicircular arch that stands (Heyman: thickness / mean radius 0.11), so it
// must: the keystone sags less than 2 cm, no stone moves 2 cm after the first second,
// and it comes to rest. Main at adce411: the keystone sags 16.6 mm in the first second,
// its joints and springings compressing 1.5 to 4.5 mm each, then the arch rests (0.1 mm
// more in 9 s); 4.2 mm at 8 substeps. This arch stood on main when the issue was filed
// too (2321258: 7 mm of sag, with stiffer 60 Hz contacts), so it guards against a
// regression but is not the arch the issue saw fall; that one is unknown.
namespace {

struct ArchRun {
    double worst_sag = 0;  // m, the keystone's, over 10 s
    double worst = 0;      // m, the most any stone moved after the first second
    double speed = 0;      // m/s, the fastest stone at the end
    bool finite = true;
};

ArchRun run_arch(const Arch& arch) {
    auto space = make_space();  // sleep off: any creep shows
    const std::vector<BodyHandle> stones = build_arch(*space, arch);
    const BodyHandle keystone = stones[static_cast<std::size_t>(arch.stones / 2)];
    const double built_y = space->internal_position(keystone).y();
    ArchRun run;
    for (int step = 0; step < 60; ++step) {  // 1 s to settle
        space->update();
        run.worst_sag = std::max(run.worst_sag, built_y - space->internal_position(keystone).y());
    }
    const std::vector<Vec3> settled = positions(*space, stones);
    for (int step = 0; step < 540; ++step) {
        space->update();
        run.worst_sag = std::max(run.worst_sag, built_y - space->internal_position(keystone).y());
        run.worst = std::max(run.worst, max_displacement(*space, stones, settled));
    }
    run.speed = max_speed(*space, stones);
    run.finite = all_finite(*space, stones);
    std::printf(
        "[ measure  ] arch of %d voussoirs, radii %.2f-%.2f m: keystone sagged %.2f mm at worst; worst stone moved "
        "%.3f mm from its pose at 1 s in 9 s; fastest at the end %.2g m/s\n",
        arch.stones, arch.inner, arch.outer, 1000 * run.worst_sag, 1000 * run.worst, run.speed);
    return run;
}

}  // namespace

TEST(Delicate, ArchOfVoussoirsStands) {
    const ArchRun run = run_arch(Arch{});
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.worst_sag, 0.02);
    EXPECT_LT(run.worst, 0.02);
    EXPECT_LT(run.speed, 0.001);
}

// A thinner arch of more stones: 21 voussoirs between radii 2 and 2.3 m (thickness over
// mean radius 0.14, above Heyman's 0.11), friction 0.6. On main when issue 16 was filed
// (2321258, this test built there) it fell: the keystone 1.99 m down. Measured at
// 8dd705a: it stands and rests (2.6 mm of movement after the first second, 2e-4 m/s at
// the end), but the keystone sags 101 mm while the soft contacts compress (each joint
// carries several stones' thrust: mm at 30 Hz) and the stones hinge on them. A rigid
// arch would not sag; this sag is the 30 Hz springs' own: 24.8 mm at 8 substeps (60 Hz),
// 6.2 mm at 16 (120 Hz), one over the stiffness squared, and Box3D (30c67b5, the same
// arch at its defaults) sags 104 mm, 25.8 and 6.6 mm at the same stiffnesses
// (docs/accuracy.md, "Delicate structures"). Asserted: no more sag than Box3D's at its
// defaults (104 mm, and 6 mm for rounding; a fall drops the keystone 2 m), and it comes
// to rest. Softer contacts fail it: 24 Hz instead of 30, 155 mm; the springings no
// stiffer than the joints (not doubled against the static floor), 112 mm.
TEST(Delicate, ThinArchOfManyVoussoirsDoesNotFall) {
    const ArchRun run = run_arch(Arch{21, 2, 2.3});
    EXPECT_TRUE(run.finite);
    EXPECT_LT(run.worst_sag, 0.11);
    EXPECT_LT(run.worst, 0.02);
    EXPECT_LT(run.speed, 0.001);
}

}  // namespace spindle::stability
