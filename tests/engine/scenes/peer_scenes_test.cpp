// The peers' benchmark scenes that were added last (configs/scenes: Box3D's rain, trees and
// large_world, Jolt's ConvexVsMesh), stepped as `spindle bench` steps them: every body stays
// finite and comes to rest where the peer's do, on the terrain or floor and none through it.
#include <spindle/engine/space.hpp>
#include <spindle/platform/assert.hpp>
#include <spindle/scene/scene.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace spindle {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(SPINDLE_SOURCE_DIR) / "configs" / "scenes";

struct Stepped {
    SceneDesc scene;
    std::unique_ptr<Space> space;
    std::vector<BodyHandle> handles;  // one per scene body
    std::vector<BodyHandle> statics;
};

// The scene built and stepped `steps` times by 1/60 s (as `spindle bench` does).
Stepped step_scene(const char* name, int steps) {
    Stepped s;
    s.scene = load_scene((kScenes / (std::string(name) + ".toml")).string());
    s.space = std::make_unique<Space>(s.scene.settings);
    s.handles = build(s.scene, *s.space);
    for (std::size_t i = 0; i < s.handles.size(); ++i) {
        if (s.scene.bodies[i].desc.type == MotionType::Static) s.statics.push_back(s.handles[i]);
    }
    for (int i = 0; i < steps; ++i) s.space->update();
    return s;
}

bool finite(const MotionState& m) {
    return m.position.allFinite() && m.orientation.coeffs().allFinite() && m.linear_velocity.allFinite() &&
           m.angular_velocity.allFinite();
}

// The height of the static geometry below p (a ray from p straight down onto static bodies
// only), or nothing where there is none: a body that went through a mesh has none below it.
std::optional<Real> ground_below(const Stepped& s, const Vec3& p) {
    QueryFilter statics;
    statics.accept = [&s](BodyHandle b) { return std::find(s.statics.begin(), s.statics.end(), b) != s.statics.end(); };
    const std::optional<QueryHit> hit = s.space->cast_ray(p, p - Vec3(0, 100, 0), statics);
    if (!hit) return std::nullopt;
    return hit->point.y();
}

struct Landing {
    std::size_t dynamic = 0;
    std::size_t off_the_ground = 0;  // no static geometry below (fell through it, or rolled off an edge)
    Real fastest = 0;                // m/s
};

Landing landing(const Stepped& s) {
    Landing l;
    for (std::size_t i = 0; i < s.handles.size(); ++i) {
        if (s.scene.bodies[i].desc.type != MotionType::Dynamic) continue;
        const MotionState m = s.space->internal_motion_state(s.handles[i]);
        EXPECT_TRUE(finite(m)) << s.scene.name << " body " << i;
        l.dynamic += 1;
        l.fastest = std::max(l.fastest, m.linear_velocity.norm());
        // From the centre of mass: a hull's origin may sit on its face (Jolt's pyramid's is on its base).
        if (!ground_below(s, m.center_of_mass)) l.off_the_ground += 1;
    }
    std::printf("%s: %zu dynamic bodies, %zu with no ground below, fastest %.3f m/s\n", s.scene.name.c_str(), l.dynamic,
                l.off_the_ground, l.fastest);
    return l;
}

// Jolt's shapes bounce (restitution 0.6) and roll about the terrain; after five seconds none has
// gone through the mesh or off its edges.
TEST(PeerScenes, ConvexVsMesh_BodiesSettleOnTheTerrain) {
    const Stepped s = step_scene("convex_vs_mesh", 300);
    const Landing l = landing(s);
    EXPECT_EQ(l.dynamic, 1764u);
    EXPECT_EQ(l.off_the_ground, 0u);
}

// Every ragdoll lands on its cell's grid or torus (some still tumbling off a torus three seconds
// in); none goes through the meshes.
TEST(PeerScenes, Rain_RagdollsLandOnTheirCells) {
    const Stepped s = step_scene("rain", 180);  // falling from 20 m takes 2 s
    const Landing l = landing(s);
    EXPECT_EQ(l.dynamic, 3600u);
    EXPECT_EQ(l.off_the_ground, 0u);
}

// The trees fall over onto the wave mesh; none goes through it.
TEST(PeerScenes, Trees_FallOntoTheWaveMesh) {
    const Stepped s = step_scene("trees", 300);
    const Landing l = landing(s);
    EXPECT_EQ(l.dynamic, 50u);
    EXPECT_EQ(l.off_the_ground, 0u);
}

// Box3D's spheres drop 0.5 m onto the floor boxes and rest on their tops (y = 0.25). Building
// a million static bodies takes this test most of its time.
TEST(PeerScenes, LargeWorld_SpheresRestOnTheFloorBoxes) {
    if (SPINDLE_VALIDATE_ENABLED) {
        // Validation checks the whole broadphase tree on every insert: a million inserts
        // would take hours. Release builds run it.
        GTEST_SKIP() << "SPINDLE_VALIDATE is on";
    }
    const Stepped s = step_scene("large_world", 90);
    std::size_t spheres = 0;
    for (std::size_t i = 0; i < s.handles.size(); ++i) {
        if (s.scene.bodies[i].desc.type != MotionType::Dynamic) continue;
        const MotionState m = s.space->internal_motion_state(s.handles[i]);
        ASSERT_TRUE(finite(m)) << "body " << i;
        EXPECT_NEAR(m.position.y(), 0.75, 0.01) << "body " << i;
        EXPECT_LT(m.linear_velocity.norm(), 0.01) << "body " << i;
        spheres += 1;
    }
    EXPECT_EQ(spheres, 100u);
}

}  // namespace
}  // namespace spindle
