// Jolt beside Spindle's tests/stability/delicate_test.cpp and scripts/peers/box3d_delicate.c:
// the same card house, the same 19 houses built with each card up to 0.5 mm off, and the
// same two arches, body for body, sleep off, at Jolt's defaults (60 Hz, one collision step,
// 10 velocity and 2 position iterations, shapes at their default convex radius: Jolt clamps
// a card's to its 1 mm half thickness). The numbers in docs/accuracy.md ("Delicate
// structures") came from it. Not part of the build (Jolt is no Debian package): build Jolt's
// library (jrouwe/JoltPhysics, cmake -S Build -B build -DCMAKE_BUILD_TYPE=Release, target Jolt),
// then
//   scripts/peers/build_jolt_delicate.sh JOLT_BUILD_DIR [OUT]   (JOLT_BUILD_DIR holds libJolt.a)
//   OUT [velocity_steps [position_steps [penetration_slop_m]]]   (Jolt's defaults: 10, 2, 0.02)
#include <Jolt/Jolt.h>

#include <Jolt/Core/Factory.h>
#include <Jolt/Core/JobSystemSingleThreaded.h>
#include <Jolt/Core/TempAllocator.h>
#include <Jolt/Physics/Body/BodyCreationSettings.h>
#include <Jolt/Physics/Collision/Shape/BoxShape.h>
#include <Jolt/Physics/Collision/Shape/ConvexHullShape.h>
#include <Jolt/Physics/PhysicsSystem.h>
#include <Jolt/RegisterTypes.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

using namespace JPH;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGap = 1e-4;  // each body is built this far above what it rests on
constexpr float kStep = 1.0f / 60;
int g_velocity_steps = -1, g_position_steps = -1;  // -1: Jolt's default
float g_penetration_slop = -1;                      // m; -1: Jolt's default

constexpr ObjectLayer kStatic = 0, kMoving = 1;

class BroadPhaseLayers final : public BroadPhaseLayerInterface {
public:
    uint GetNumBroadPhaseLayers() const override { return 2; }
    BroadPhaseLayer GetBroadPhaseLayer(ObjectLayer layer) const override { return BroadPhaseLayer(layer); }
#if defined(JPH_EXTERNAL_PROFILE) || defined(JPH_PROFILE_ENABLED)
    const char* GetBroadPhaseLayerName(BroadPhaseLayer layer) const override {
        return layer == BroadPhaseLayer(kStatic) ? "static" : "moving";
    }
#endif
};

class ObjectVsBroadPhase final : public ObjectVsBroadPhaseLayerFilter {
public:
    bool ShouldCollide(ObjectLayer a, BroadPhaseLayer b) const override {
        return a == kMoving || b == BroadPhaseLayer(kMoving);
    }
};

class ObjectPairs final : public ObjectLayerPairFilter {
public:
    bool ShouldCollide(ObjectLayer a, ObjectLayer b) const override { return a == kMoving || b == kMoving; }
};

// One Jolt world, stepped on one thread.
class World {
public:
    World() : m_temp(32 * 1024 * 1024) {
        m_system.Init(1024, 0, 4096, 4096, m_layers, m_object_vs_broadphase, m_pairs);
        PhysicsSettings settings = m_system.GetPhysicsSettings();
        settings.mAllowSleeping = false;
        if (g_velocity_steps > 0) settings.mNumVelocitySteps = static_cast<uint>(g_velocity_steps);
        if (g_position_steps >= 0) settings.mNumPositionSteps = static_cast<uint>(g_position_steps);
        if (g_penetration_slop >= 0) settings.mPenetrationSlop = g_penetration_slop;
        m_system.SetPhysicsSettings(settings);
    }

    BodyInterface& bodies() { return m_system.GetBodyInterface(); }

    BodyID add(const Shape* shape, RVec3 position, Quat rotation, bool dynamic, float friction) {
        BodyCreationSettings settings(shape, position, rotation, dynamic ? EMotionType::Dynamic : EMotionType::Static,
                                      dynamic ? kMoving : kStatic);
        settings.mFriction = friction;
        settings.mRestitution = 0;
        settings.mAllowSleeping = false;
        return bodies().CreateAndAddBody(settings, dynamic ? EActivation::Activate : EActivation::DontActivate);
    }

    void step() { m_system.Update(kStep, 1, &m_temp, &m_jobs); }

private:
    BroadPhaseLayers m_layers;
    ObjectVsBroadPhase m_object_vs_broadphase;
    ObjectPairs m_pairs;
    PhysicsSystem m_system;
    TempAllocatorImpl m_temp;
    JobSystemSingleThreaded m_jobs{cMaxPhysicsJobs};
};

RefConst<Shape> make(const ShapeSettings& settings) {
    ShapeSettings::ShapeResult result = settings.Create();
    if (result.HasError()) {
        std::fprintf(stderr, "jolt_delicate: %s\n", result.GetError().c_str());
        std::exit(1);
    }
    return result.Get();
}

RefConst<Shape> box(Vec3 half, float density) {
    BoxShapeSettings settings(half);  // the default convex radius, clamped by Jolt to the smallest half extent
    settings.mDensity = density;
    return make(settings);
}

Quat about_z(double angle) { return Quat::sRotation(Vec3::sAxisZ(), static_cast<float>(angle)); }

// Uniform in [-1, 1), the same sequence as delicate_test.cpp's (splitmix64).
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

// A playing card: 88 x 63 x 2 mm, 700 kg/m^3, friction 0.5.
constexpr double ca = 0.044, cb = 0.001, cc = 0.0315;

double top_of_card(World& world, BodyID card) {
    const RVec3 p = world.bodies().GetPosition(card);
    const Mat44 r = Mat44::sRotation(world.bodies().GetRotation(card));
    // the y row of the rotation against the half extents
    return p.GetY() + std::fabs(r(1, 0)) * ca + std::fabs(r(1, 1)) * cb + std::fabs(r(1, 2)) * cc;
}

// The angle a card has turned from the orientation it was built with.
double turned(World& world, BodyID card, Quat built) {
    const Quat d = built.Conjugated() * world.bodies().GetRotation(card);
    return 2 * std::atan2(d.GetXYZ().Length(), std::fabs(d.GetW()));
}

struct HouseRun {
    double drop_1s = 0, worst_drop = 0, end_drop = 0, racking = 0, speed = 0;  // m, m, m, radians, m/s
    int cards = 0;
};

// Built as delicate_test.cpp's build_card_house; off > 0 moves each card up to off along x at random (seed).
HouseRun card_house(int levels, int steps, double off, std::uint64_t seed) {
    World world;
    world.add(box(Vec3(1, 0.5f, 1), 1000), RVec3(0, -0.5f, 0), Quat::sIdentity(), false, 0.5f);
    const RefConst<Shape> card = box(Vec3(ca, cb, cc), 700);
    Jitter jitter(seed);
    auto shift = [&] { return off > 0 ? off * jitter() : 0.0; };
    const double lean = 68 * kPi / 180, c = std::cos(lean), s = std::sin(lean);
    const double spacing = 2 * ca + kGap, pair_height = 2 * ca * s + 2 * cb * c;
    std::vector<BodyID> cards;
    BodyID top[2];
    double floor_y = 0;
    auto add = [&](double x, double y, double angle) {
        const BodyID id = world.add(card, RVec3(static_cast<float>(x + shift()), static_cast<float>(y), 0),
                                    about_z(angle), true, 0.5f);
        cards.push_back(id);
        return id;
    };
    for (int level = 0; level < levels; ++level) {
        const int pairs = levels - level;
        const double centre_y = floor_y + kGap + ca * s + cb * c;
        for (int j = 0; j < pairs; ++j) {
            const double apex = (j - 0.5 * (pairs - 1)) * spacing, half = ca * c + cb * s;
            top[0] = add(apex - half, centre_y, lean);
            top[1] = add(apex + half, centre_y, -lean);
        }
        const double flat_y = floor_y + kGap + pair_height + kGap + cb;
        for (int j = 0; j + 1 < pairs; ++j) add((j - 0.5 * (pairs - 1)) * spacing + 0.5 * spacing, flat_y, 0);
        floor_y = flat_y + cb;
    }
    auto top_y = [&] { return std::max(top_of_card(world, top[0]), top_of_card(world, top[1])); };
    const double built = top_y();
    const Quat built_top[2] = {world.bodies().GetRotation(top[0]), world.bodies().GetRotation(top[1])};
    HouseRun run;
    run.cards = static_cast<int>(cards.size());
    for (int step = 0; step < steps; ++step) {
        world.step();
        run.worst_drop = std::max(run.worst_drop, built - top_y());
        run.racking = std::max({run.racking, turned(world, top[0], built_top[0]), turned(world, top[1], built_top[1])});
        if (step == 59) run.drop_1s = built - top_y();
    }
    run.end_drop = built - top_y();
    for (BodyID id : cards) run.speed = std::max(run.speed, double(world.bodies().GetLinearVelocity(id).Length()));
    return run;
}

void arch(int stones, double inner, double outer) {
    World world;
    world.add(box(Vec3(5, 0.5f, 2), 1000), RVec3(0, -0.5f, 0), Quat::sIdentity(), false, 0.6f);
    std::vector<BodyID> body;
    for (int i = 0; i < stones; ++i) {
        const double from = i * kPi / stones, to = (i + 1) * kPi / stones, mid = 0.5 * (from + to);
        const double r_mid = 0.5 * (inner + outer), ox = r_mid * std::cos(mid), oy = r_mid * std::sin(mid);
        Array<Vec3> points;
        for (double r : {inner, outer})
            for (double angle : {from, to})
                for (double z : {-0.5, 0.5})
                    points.push_back(Vec3(static_cast<float>(r * std::cos(angle) - ox),
                                          static_cast<float>(r * std::sin(angle) - oy), static_cast<float>(z)));
        ConvexHullShapeSettings settings(points);  // the default convex radius
        settings.mDensity = 2500;
        body.push_back(world.add(make(settings), RVec3(static_cast<float>(ox), static_cast<float>(oy + kGap), 0),
                                 Quat::sIdentity(), true, 0.6f));
    }
    const BodyID key = body[static_cast<std::size_t>(stones / 2)];
    const double built = world.bodies().GetPosition(key).GetY();
    double worst = 0, at1 = 0;
    for (int step = 0; step < 600; ++step) {
        world.step();
        const double sag = built - world.bodies().GetPosition(key).GetY();
        worst = std::max(worst, sag);
        if (step == 59) at1 = sag;
    }
    double speed = 0;
    for (BodyID id : body) speed = std::max(speed, double(world.bodies().GetLinearVelocity(id).Length()));
    std::printf(
        "jolt arch of %d voussoirs, radii %.2f-%.2f: keystone sag %.2f mm at 1 s, %.2f mm worst, %.2f mm end; fastest "
        "at end %.2g m/s\n",
        stones, inner, outer, 1000 * at1, 1000 * worst,
        1000 * (built - world.bodies().GetPosition(key).GetY()), speed);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1) g_velocity_steps = std::atoi(argv[1]);
    if (argc > 2) g_position_steps = std::atoi(argv[2]);
    if (argc > 3) g_penetration_slop = static_cast<float>(std::atof(argv[3]));
    RegisterDefaultAllocator();
    Factory::sInstance = new Factory();
    RegisterTypes();

    const HouseRun house = card_house(5, 600, 0, 0);
    std::printf(
        "jolt card house 5 levels (%d cards): top drop %.2f mm at 1 s, %.2f mm worst, %.2f mm end; top pair racked "
        "%.2f deg at worst; fastest at end %.2g m/s\n",
        house.cards, 1000 * house.drop_1s, 1000 * house.worst_drop, 1000 * house.end_drop,
        house.racking * 180 / kPi, house.speed);
    // As Delicate.CardHousesBuiltSlightlyOffKeepTheirTopPair: 5 s each, a house keeps its top
    // pair with its top less than 2 cm down and the pair racked less than 20 degrees.
    int fallen = 0;
    for (std::uint64_t seed = 1; seed <= 19; ++seed) {
        const HouseRun run = card_house(5, 300, 0.0005, seed);
        const bool stands = std::isfinite(run.worst_drop) && run.worst_drop < 0.02 && run.racking < 20 * kPi / 180;
        fallen += stands ? 0 : 1;
        std::printf("jolt card house, seed %2d: top dropped %.2f mm at worst, top pair racked %.2f degrees%s\n",
                    static_cast<int>(seed), 1000 * run.worst_drop, run.racking * 180 / kPi, stands ? "" : ": fell");
    }
    std::printf("jolt card houses built up to 0.5 mm off: %d of 19 lost their top pair\n", fallen);
    arch(11, 2, 2.5);
    arch(21, 2, 2.3);
    UnregisterTypes();
    delete Factory::sInstance;
    Factory::sInstance = nullptr;
    return 0;
}
