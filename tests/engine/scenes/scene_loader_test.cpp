// Scene files: every file in configs/scenes parses and builds, the built-in scenes
// are what they claim, broken files are rejected at the right line and column, and
// build() is all or nothing.
#include <spindle/engine/space.hpp>
#include <spindle/platform/assert.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "scene_test_util.hpp"

namespace spindle {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(SPINDLE_SOURCE_DIR) / "configs" / "scenes";

std::vector<std::filesystem::path> scene_files() {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(kScenes)) {
        if (entry.path().extension() == ".toml") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

SceneDesc load(const char* name) { return load_scene((kScenes / (std::string(name) + ".toml")).string()); }

// The message of the spindle::Error that building `scene` throws.
std::string build_error(const SceneDesc& scene, Space& space) {
    try {
        build(scene, space);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(SceneFiles, EveryConfigScene_Parses) {
    const std::vector<std::filesystem::path> files = scene_files();
    ASSERT_GE(files.size(), 7u);
    for (const auto& file : files) {
        SCOPED_TRACE(file.string());
        const SceneDesc scene = load_scene(file.string());
        EXPECT_EQ(scene.name, file.stem().string());
        EXPECT_FALSE(scene.description.empty());
        EXPECT_GT(scene.dynamic_body_count(), 0u);
        for (const SceneBody& body : scene.bodies) ASSERT_LT(body.shape, scene.shapes.size());
    }
}

TEST(SceneFiles, EveryConfigScene_BuildsAndSteps) {
    for (const auto& file : scene_files()) {
        SCOPED_TRACE(file.string());
        const SceneDesc scene = load_scene(file.string());
        if (SPINDLE_VALIDATE_ENABLED && scene.bodies.size() > 5000) {
            // With validation on (debug and sanitizer builds) every insert checks the
            // whole broadphase tree, so 10k bodies cost minutes; Release builds them.
            continue;
        }
        Space space;
        const std::vector<BodyHandle> handles = build(scene, space);
        ASSERT_EQ(handles.size(), scene.bodies.size());
        EXPECT_EQ(space.body_count(), scene.bodies.size());
        for (std::size_t i = 0; i < handles.size(); i += 97) {
            // A hull whose centre of mass is off its origin is stored by that centre: the
            // origin read back is within rounding of the one given.
            const Vec3& given = scene.bodies[i].desc.position;
            EXPECT_LE((space.internal_position(handles[i]) - given).norm(), 1e-12 * (1 + given.norm()));
        }
        if (scene.bodies.size() < 1000) {  // the big ones are stepped by the program's tests and bench
            for (int i = 0; i < 3; ++i) space.update();
        }
    }
}

TEST(SceneFiles, Pyramid_IsJoltsPerformanceTestPyramid) {
    const SceneDesc scene = load("pyramid");
    ASSERT_EQ(scene.bodies.size(), 1241u);
    EXPECT_EQ(scene.dynamic_body_count(), 1240u);

    const SceneBody& floor = scene.bodies[0];
    EXPECT_EQ(floor.desc.type, MotionType::Static);
    EXPECT_EQ(scene.shapes[floor.shape].type, ShapeType::Box);
    EXPECT_EQ(scene.shapes[floor.shape].half_extents, Vec3(50, 1, 50));
    EXPECT_EQ(floor.desc.position, Vec3(0, -1, 0));

    // Jolt's loops, written out again here.
    std::vector<Vec3> expected;
    for (int i = 0; i < 15; ++i) {
        for (int j = i / 2; j < 15 - (i + 1) / 2; ++j) {
            for (int k = i / 2; k < 15 - (i + 1) / 2; ++k) {
                const double h = (i & 1) ? 1 : 0;
                expected.emplace_back(-15 + 2 * j + h, 1 + 2.5 * i, -15 + 2 * k + h);
            }
        }
    }
    ASSERT_EQ(expected.size(), 1240u);
    for (std::size_t n = 0; n < expected.size(); ++n) {
        const SceneBody& box = scene.bodies[n + 1];
        ASSERT_EQ(box.desc.type, MotionType::Dynamic);
        ASSERT_TRUE(box.desc.position.isApprox(expected[n], 1e-12)) << "box " << n;
        ASSERT_EQ(scene.shapes[box.shape].half_extents, Vec3(1, 1, 1));
        ASSERT_EQ(box.desc.friction, 0.2);
        ASSERT_FALSE(box.desc.allow_sleep);
    }
    // A few by hand: the first box, the first of layer 1 (odd: shifted by 1), the top.
    EXPECT_EQ(scene.bodies[1].desc.position, Vec3(-15, 1, -15));
    EXPECT_EQ(scene.bodies[1 + 225].desc.position, Vec3(-14, 3.5, -14));
    EXPECT_EQ(scene.bodies.back().desc.position, Vec3(-1, 36, -1));
}

TEST(SceneFiles, ManyPyramids_Has196PyramidsOf55HalfMetreCubes) {
    const SceneDesc scene = load("many_pyramids");
    EXPECT_EQ(scene.dynamic_body_count(), 10780u);
    for (const SceneBody& b : scene.bodies) {
        if (b.desc.type == MotionType::Dynamic) {
            ASSERT_EQ(scene.shapes[b.shape].half_extents, Vec3::Constant(0.5));
        }
    }
}

TEST(SceneFiles, OtherScenes_HaveWhatTheyPromise) {
    EXPECT_EQ(load("stack").dynamic_body_count(), 20u);
    EXPECT_EQ(load("dominoes").dynamic_body_count(), 40u);
    const SceneDesc bullets = load("bullets");
    for (const SceneBody& b : bullets.bodies) {
        if (b.desc.type == MotionType::Dynamic) {
            EXPECT_TRUE(b.desc.fast);
            EXPECT_EQ(bullets.shapes[b.shape].type, ShapeType::Sphere);
        }
    }
    const SceneDesc pile = load("pile");
    std::vector<bool> seen(static_cast<int>(ShapeType::Count), false);
    for (const SceneBody& b : pile.bodies) seen[static_cast<int>(pile.shapes[b.shape].type)] = true;
    for (ShapeType t :
         {ShapeType::Sphere, ShapeType::Box, ShapeType::Capsule, ShapeType::ConvexHull, ShapeType::TriangleMesh}) {
        EXPECT_TRUE(seen[static_cast<int>(t)]) << to_string(t);
    }
    const SceneDesc mass_ratio = load("mass_ratio");
    double lightest = 1e300, heaviest = 0;
    for (const SceneBody& b : mass_ratio.bodies) {
        if (b.desc.type != MotionType::Dynamic) continue;
        lightest = std::min(lightest, b.desc.mass);
        heaviest = std::max(heaviest, b.desc.mass);
    }
    EXPECT_GE(heaviest / lightest, 100);
}

TEST(SceneFiles, Box3DBenchmarkScenes_HaveBox3DsDynamicBodies) {
    // Box3D's benchmark program (shared/benchmarks.c at 30c67b5, its Release sizes).
    EXPECT_EQ(load("large_pyramid").dynamic_body_count(), 5050u);
    EXPECT_EQ(load("convex_pile").dynamic_body_count(), 5120u);
    EXPECT_EQ(load("washer").dynamic_body_count(), 8000u);
    EXPECT_EQ(load("junkyard").dynamic_body_count(), 10584u);
    const SceneDesc joint_grid = load("joint_grid");
    EXPECT_EQ(joint_grid.dynamic_body_count(), 9900u);
    EXPECT_EQ(joint_grid.joints.size(), 9900u);  // the columns' joints; Box3D's net has 19,800

    // rain: the full grid of Box3D's Release build, 10 x 10 cells of 3 humans, all at once.
    const SceneDesc rain = load("rain");
    EXPECT_EQ(rain.dynamic_body_count(), 300u * 12u);
    EXPECT_EQ(rain.joints.size(), 300u * 11u);
    EXPECT_EQ(rain.bodies.size() - rain.dynamic_body_count(), 200u);  // a grid mesh and a torus per cell
    for (const SceneBody& b : rain.bodies) {
        if (b.desc.type == MotionType::Static) {
            ASSERT_EQ(rain.shapes[b.shape].type, ShapeType::TriangleMesh);
        }
    }

    const SceneDesc trees = load("trees");
    EXPECT_EQ(trees.dynamic_body_count(), 50u);
    for (const SceneBody& b : trees.bodies) {
        if (b.desc.type != MotionType::Dynamic) continue;
        ASSERT_EQ(trees.shapes[b.shape].type, ShapeType::Compound);
        ASSERT_EQ(trees.shapes[b.shape].parts.size(), 22u);
        ASSERT_EQ(b.desc.density, 1.0);
        ASSERT_EQ(b.desc.friction, 0.9);
        ASSERT_EQ(b.desc.rolling_resistance, 0.05);  // Box3D's tree material
    }

    const SceneDesc large_world = load("large_world");
    EXPECT_EQ(large_world.dynamic_body_count(), 100u);
    EXPECT_EQ(large_world.bodies.size(), 1'000'100u);
}

// Jolt's PerformanceTest "ConvexVsMesh": 21 x 21 of each of four shapes over a 100 x 100 cell
// terrain whose vertex (ix, iz) is at (3 ix - 150, 5 + 5 sin(ix / 2) cos(iz / 2), 3 iz - 150).
TEST(SceneFiles, ConvexVsMesh_IsJoltsScene) {
    const SceneDesc scene = load("convex_vs_mesh");
    EXPECT_EQ(scene.dynamic_body_count(), 1764u);
    std::array<int, static_cast<int>(ShapeType::Count)> per_type{};
    for (const SceneBody& b : scene.bodies) {
        ASSERT_EQ(b.desc.friction, 0.5);
        ASSERT_EQ(b.desc.restitution, 0.6);
        if (b.desc.type == MotionType::Dynamic) per_type[static_cast<int>(scene.shapes[b.shape].type)] += 1;
    }
    for (ShapeType t : {ShapeType::Box, ShapeType::Sphere, ShapeType::Capsule, ShapeType::ConvexHull}) {
        EXPECT_EQ(per_type[static_cast<int>(t)], 441) << to_string(t);
    }
    const SceneBody& terrain = scene.bodies[0];
    ASSERT_EQ(terrain.desc.type, MotionType::Static);
    EXPECT_EQ(terrain.desc.position, Vec3(0, 5, 0));
    const ShapeSpec& mesh = scene.shapes[terrain.shape];
    ASSERT_EQ(mesh.points.size(), 101u * 101u);
    EXPECT_EQ(mesh.indices.size(), 3u * 2u * 100u * 100u);
    for (const auto& [ix, iz] : {std::pair{0, 0}, {1, 0}, {7, 3}, {100, 100}}) {
        const Vec3& p = mesh.points[static_cast<std::size_t>(iz * 101 + ix)];
        EXPECT_NEAR(p.x(), 3.0 * ix - 150, 1e-9);
        EXPECT_NEAR(p.z(), 3.0 * iz - 150, 1e-9);
        EXPECT_NEAR(p.y(), 5 * std::sin(0.5 * ix) * std::cos(0.5 * iz), 1e-5) << ix << ", " << iz;
    }
}

TEST(SceneParse, EveryShape_IsRead) {
    const SceneDesc scene = parse_scene(R"(
[[body]]
shape = { capsule = { half_height = 0.5, radius = 0.25 } }
[[body]]
shape = { hull = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]] }
[[body]]
type = "static"
shape = { plane = { normal = [0, 2, 0], offset = -1 } }
[[body]]
type = "static"
shape = { mesh = { vertices = [[0, 0, 0], [1, 0, 0], [0, 0, 1]], triangles = [[0, 2, 1]] } }
[[body]]
type = "static"
shape = { heightfield = { size = [10, 20], cells = [4, 2], amplitude = 1, wavelength = 5 } }
[[body]]
type = "static"
shape = { heightfield = { size = [2, 2], heights = [[0, 1], [2, 3]] } }
)",
                                        "shapes.toml");
    ASSERT_EQ(scene.shapes.size(), 6u);
    EXPECT_EQ(scene.shapes[0].type, ShapeType::Capsule);
    EXPECT_EQ(scene.shapes[0].half_height, 0.5);
    EXPECT_EQ(scene.shapes[0].radius, 0.25);
    EXPECT_EQ(scene.shapes[1].type, ShapeType::ConvexHull);
    EXPECT_EQ(scene.shapes[1].points.size(), 4u);
    EXPECT_EQ(scene.shapes[2].type, ShapeType::Plane);
    EXPECT_EQ(scene.shapes[2].normal, Vec3(0, 1, 0));
    EXPECT_EQ(scene.shapes[2].offset, -1);
    EXPECT_EQ(scene.shapes[3].type, ShapeType::TriangleMesh);
    EXPECT_EQ(scene.shapes[3].indices, (std::vector<std::uint32_t>{0, 2, 1}));

    const ShapeSpec& field = scene.shapes[4];
    EXPECT_EQ(field.type, ShapeType::TriangleMesh);
    EXPECT_EQ(field.points.size(), 5u * 3u);
    EXPECT_EQ(field.indices.size(), 4u * 2u * 6u);
    for (std::size_t t = 0; t < field.indices.size(); t += 3) {  // every triangle faces up
        const Vec3& a = field.points[field.indices[t]];
        const Vec3 n = (field.points[field.indices[t + 1]] - a).cross(field.points[field.indices[t + 2]] - a);
        EXPECT_GT(n.y(), 0);
    }
    EXPECT_TRUE(field.points.front().isApprox(Vec3(-5, 0, -10), 1e-12));
    const ShapeSpec& listed = scene.shapes[5];
    ASSERT_EQ(listed.points.size(), 4u);
    EXPECT_EQ(listed.points[3], Vec3(1, 3, 1));  // row 1 (z = +1), column 1 (x = +1)
}

// Box3D's wave mesh (the trees scene) waves at one wavelength along x and another along z.
TEST(SceneParse, HeightfieldWithTwoWavelengths_WavesAtEachAlongItsAxis) {
    const SceneDesc scene = parse_scene(R"(
[[body]]
type = "static"
shape = { heightfield = { size = [20, 40], cells = [8, 16], amplitude = -0.5, wavelength = [10, 20] } }
)",
                                        "waves.toml");
    const ShapeSpec& field = scene.shapes.at(0);
    ASSERT_EQ(field.points.size(), 9u * 17u);
    for (const Vec3& p : field.points) {
        ASSERT_NEAR(p.y(), -0.5 * std::sin(2 * kPi * p.x() / 10) * std::sin(2 * kPi * p.z() / 20), 1e-12)
            << p.transpose();
    }
    // x = -2.5, z = -5: a quarter wavelength from the centre on both axes, the lowest point.
    EXPECT_NEAR(field.points[6 * 9 + 3].y(), -0.5, 1e-12);
    EXPECT_REJECTED("[[body]]\ntype = \"static\"\nshape = { heightfield = { size = [1, 1], cells = [1, 1], "
                    "wavelength = [10, 0] } }\n",
                    "3:76", "body.shape.heightfield.wavelength: expected numbers > 0 [wx, wz in m], got 0");
    EXPECT_REJECTED("[[body]]\ntype = \"static\"\nshape = { heightfield = { size = [1, 1], cells = [1, 1], "
                    "wavelength = [10] } }\n",
                    "3:71", "body.shape.heightfield.wavelength: expected an array of 2 numbers");
}

TEST(SceneParse, Compound_IsReadAndBuilt) {
    const SceneDesc scene = parse_scene(R"(
[[body]]
position = [0, 2, 0]
shape = { compound = [
  { shape = { box = [1, 0.1, 0.5] }, position = [0, 0.5, 0] },
  { shape = { sphere = 0.25 }, position = [0.5, 0, 0], orientation = [2, 0, 0, 0] },
  { shape = { capsule = { half_height = 0.3, radius = 0.1 } }, orientation = { axis = [0, 0, 1], degrees = 90 } },
] }
)",
                                        "compound.toml");
    ASSERT_EQ(scene.shapes.size(), 1u);
    const ShapeSpec& spec = scene.shapes[0];
    EXPECT_EQ(spec.type, ShapeType::Compound);
    ASSERT_EQ(spec.parts.size(), 3u);
    EXPECT_EQ(spec.parts[0].shape.type, ShapeType::Box);
    EXPECT_EQ(spec.parts[0].position, Vec3(0, 0.5, 0));
    EXPECT_EQ(spec.parts[1].orientation.coeffs(), Quat::Identity().coeffs());  // normalised
    EXPECT_EQ(spec.parts[2].position, Vec3::Zero());
    EXPECT_LT((spec.parts[2].orientation * Vec3::UnitY() - Vec3(-1, 0, 0)).norm(), 1e-12);
    // The box's half width plus its position, under a quarter turn about y.
    const Vec3 half = spec.half_size(Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitY())));
    EXPECT_NEAR(half.z(), 1, 1e-12);
    EXPECT_NEAR(half.y(), 0.425, 1e-12);  // from the sphere's bottom at -0.25 to the box's top at 0.6

    Space space;
    const std::vector<BodyHandle> bodies = build(scene, space);
    ASSERT_EQ(bodies.size(), 1u);
    EXPECT_EQ(space.internal_desc(bodies[0]).shape.type, ShapeType::Compound);
}

TEST(SceneParse, BrokenCompounds_AreRejectedAtTheLineAndColumn) {
    EXPECT_REJECTED("[[body]]\nshape = { compound = [] }\n", "2:22", "body.shape.compound: expected at least one part");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { sphere = 0 } }] }\n", "2:44",
                    "body.shape.compound[0].shape.sphere: expected a number > 0");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { sphere = 1 } }, { shape = { box = [1, 0, 1] } }] }\n",
                    "2:73", "body.shape.compound[1].shape.box: expected numbers > 0");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { plane = { normal = [0, 1, 0] } } }] }\n", "2:33",
                    "body.shape.compound[0].shape: a compound part must be a sphere, box, capsule or hull, got plane");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { compound = [{ shape = { sphere = 1 } }] } }] }\n",
                    "2:33", "a compound part must be a sphere, box, capsule or hull, got compound");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { sphere = 1 }, rotation = [1, 0, 0, 0] }] }\n", "2:49",
                    "unknown key 'rotation' in body.shape.compound[0]");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ position = [0, 0, 0] }] }\n", "2:23",
                    "body.shape.compound[0]: missing key 'shape'");
    EXPECT_REJECTED("[[body]]\nshape = { compound = [{ shape = { sphere = 1 }, orientation = [0, 0, 0, 0] }] }\n",
                    "2:63", "body.shape.compound[0].orientation: expected a non-zero quaternion");
    EXPECT_REJECTED("[[body]]\nshape = { compound = { shape = { sphere = 1 } } }\n", "2:22",
                    "body.shape.compound: expected an array");
}

TEST(SceneBuild, CompoundWithAFlatHullPart_NamesThePartAndTheLine) {
    const SceneDesc scene = parse_scene("\n\n\n[[body]]\nshape = { compound = [{ shape = { sphere = 1 } }, "
                                        "{ shape = { hull = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]] } }] }\n",
                                        "flat.toml");
    Space space;
    const std::string message = build_error(scene, space);
    EXPECT_NE(message.find("flat.toml:4:1: shape: compound: part 1: "), std::string::npos) << message;
    EXPECT_EQ(space.body_count(), 0u);
}

TEST(SceneParse, BodyProperties_DefaultsThenEntryKeys) {
    const SceneDesc scene = parse_scene(R"(
[defaults]
shape = { sphere = 0.5 }
friction = 0.1
restitution = 0.5
rolling_resistance = 0.02
allow_sleep = false

[[body]]
friction = 0.9
rolling_resistance = 0.3
type = "kinematic"
orientation = { axis = [0, 0, 2], degrees = 90 }
velocity = [1, 2, 3]
angular_velocity = [0, 1, 0]
density = 500
gravity_scale = -1
linear_damping = 0.1
angular_damping = 0.2
gyroscopic = true
allow_interpolation = false
fast = true
lock_translation = ["z"]
lock_rotation = ["y", "x"]

[[body]]
shape = { box = [1, 2, 3] }
mass = 7
orientation = [2, 0, 0, 0]
)",
                                        "defaults.toml");
    EXPECT_EQ(scene.name, "defaults");
    ASSERT_EQ(scene.bodies.size(), 2u);
    const BodyDesc& a = scene.bodies[0].desc;
    EXPECT_EQ(a.type, MotionType::Kinematic);
    EXPECT_EQ(a.friction, 0.9);
    EXPECT_EQ(a.restitution, 0.5);
    EXPECT_EQ(a.rolling_resistance, 0.3);
    EXPECT_FALSE(a.allow_sleep);
    EXPECT_TRUE(a.orientation.isApprox(Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ())), 1e-12));
    EXPECT_EQ(a.linear_velocity, Vec3(1, 2, 3));
    EXPECT_EQ(a.angular_velocity, Vec3(0, 1, 0));
    EXPECT_EQ(a.density, 500);
    EXPECT_EQ(a.gravity_scale, -1);
    EXPECT_EQ(a.linear_damping, 0.1);
    EXPECT_EQ(a.angular_damping, 0.2);
    EXPECT_TRUE(a.gyroscopic);
    EXPECT_FALSE(a.allow_interpolation);
    EXPECT_TRUE(a.fast);
    EXPECT_EQ(a.locks, MotionLocks::plane_xy());
    EXPECT_EQ(scene.shapes[scene.bodies[0].shape].type, ShapeType::Sphere);

    const BodyDesc& b = scene.bodies[1].desc;
    EXPECT_EQ(b.friction, 0.1);
    EXPECT_EQ(b.rolling_resistance, 0.02);
    EXPECT_EQ(b.mass, 7);
    EXPECT_EQ(b.type, MotionType::Dynamic);
    EXPECT_TRUE(b.orientation.isApprox(Quat::Identity()));  // normalised
    EXPECT_EQ(scene.shapes[scene.bodies[1].shape].type, ShapeType::Box);
    EXPECT_EQ(b.linear_velocity, Vec3::Zero());
    EXPECT_FALSE(b.locks.any());
}

TEST(SceneParse, Settings_AreRead) {
    const SceneDesc scene = parse_scene(R"(
name = "tuned"
description = "every setting"
[settings]
gravity = [0, -1.62, 0]
time_step = 0.01
max_steps_per_frame = 4
min_steps_per_frame = 1
substeps = 8
iterations = 2
relax_iterations = 0
contact_hertz = 60
contact_damping_ratio = 5
joint_hertz = 0
joint_damping_ratio = 1
push_out_speed = 1.5
recovery_depth = 0.05
restitution_threshold = 0.5
speculative_distance = 0.02
linear_slop = 0.001
sleep = false
time_to_sleep = 2
sleep_linear_threshold = 0.01
sleep_angular_threshold = 0.02
capacity.contact_count = 60000
)",
                                        "x.toml");
    EXPECT_EQ(scene.name, "tuned");
    EXPECT_EQ(scene.description, "every setting");
    const SpaceSettings& s = scene.settings;
    EXPECT_EQ(s.gravity, Vec3(0, -1.62, 0));
    EXPECT_EQ(s.time_step.duration, 0.01);
    EXPECT_EQ(s.time_step.max_steps_per_frame, 4);
    EXPECT_EQ(s.time_step.min_steps_per_frame, 1);
    EXPECT_EQ(s.solver.substeps, 8);
    EXPECT_EQ(s.solver.iterations, 2);
    EXPECT_EQ(s.solver.relax_iterations, 0);
    EXPECT_EQ(s.solver.contact_hertz, 60);
    EXPECT_EQ(s.solver.damping_ratio, 5);
    EXPECT_EQ(s.solver.joint_hertz, 0);
    EXPECT_EQ(s.solver.joint_damping_ratio, 1);
    EXPECT_EQ(s.solver.push_out_speed, 1.5);
    EXPECT_EQ(s.solver.recovery_depth, 0.05);
    EXPECT_EQ(s.solver.restitution_threshold, 0.5);
    EXPECT_EQ(s.solver.speculative_distance, 0.02);
    EXPECT_EQ(s.solver.linear_slop, 0.001);
    EXPECT_FALSE(s.sleep.enabled);
    EXPECT_EQ(s.sleep.time_to_sleep, 2);
    EXPECT_EQ(s.sleep.linear_threshold, 0.01);
    EXPECT_EQ(s.sleep.angular_threshold, 0.02);
    EXPECT_EQ(s.capacity.contact_count, 60000);
    EXPECT_TRUE(scene.bodies.empty());
}

TEST(SceneParse, Entries_ExpandInFileOrder) {
    const SceneDesc scene = parse_scene(R"(
[defaults]
shape = { box = [0.5, 0.25, 0.5] }

[[body]]
position = [100, 0, 0]

[[stack]]
count = 3
position = [0, 0.25, 0]
gap = 0.1

[[body]]
position = [1, 2, 3]
copies = { count = [2, 1, 3], step = [10, 0, 20] }

[[pyramid_2d]]
base = 3
position = [0, 0, 5]

[[stack]]
count = 2
spacing = 4
)",
                                        "order.toml");
    std::vector<Vec3> expected = {{100, 0, 0},   {0, 0.25, 0}, {0, 0.85, 0}, {0, 1.45, 0},  // 0.5 high + 0.1 gap
                                  {1, 2, 3},     {11, 2, 3},   {1, 2, 23},   {11, 2, 23},
                                  {1, 2, 43},    {11, 2, 43},  // x fastest
                                  {0, 0, 5},     {1, 0, 5},    {2, 0, 5},    {0.5, 0.5, 5},
                                  {1.5, 0.5, 5}, {1, 1, 5},    {0, 0, 0},    {0, 4, 0}};
    ASSERT_EQ(scene.bodies.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_TRUE(scene.bodies[i].desc.position.isApprox(expected[i], 1e-12))
            << i << ": " << scene.bodies[i].desc.position.transpose();
    }
    EXPECT_EQ(scene.bodies[0].line, 5u);  // the [[body]] header
    EXPECT_EQ(scene.shapes.size(), 1u);   // one shape shared by every body
}

TEST(SceneParse, BrokenScenes_AreRejectedAtTheLineAndColumn) {
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nfrction = 0.2\n", "3:1", "unknown key 'frction' in [[body]]");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nfriction = \"high\"\n", "3:12",
                    "body.friction: expected a number, got a string");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = -1 }\n", "2:20", "body.shape.sphere: expected a number > 0");
    EXPECT_REJECTED("[[body]]\nshape = { box = [1, 1] }\n", "2:17", "body.shape.box: expected an array of 3 numbers");
    EXPECT_REJECTED("[[body]]\nshape = { box = [1, 0, 1] }\n", "2:21", "expected numbers > 0");
    EXPECT_REJECTED("[[body]]\nshape = { cube = 1 }\n", "2:11", "unknown key 'cube' in body.shape");
    EXPECT_REJECTED("[[body]]\nshape = { plane = { normal = [0, 1, 0] } }\n", "2:9",
                    "a plane can only belong to a static body");
    EXPECT_REJECTED("[[body]]\nposition = [0, 1, 0]\n", "1:1", "body: missing key 'shape'");
    EXPECT_REJECTED("[setings]\nsubsteps = 4\n", "1:2", "unknown key 'setings' in the scene");
    EXPECT_REJECTED("[settings]\nsubsteps = 0\n", "2:12", "settings.substeps: expected an integer in [1, 1000], got 0");
    EXPECT_REJECTED("[settings]\ntime_step = -0.01\n", "2:13", "settings.time_step: expected a number > 0");
    EXPECT_REJECTED("[settings]\nsleep = 1\n", "2:9", "settings.sleep: expected true or false");
    EXPECT_REJECTED("[settings]\ncapacity.contact_count = -1\n", "2:26",
                    "settings.capacity.contact_count: expected an integer in [0, 4294967295], got -1");
    EXPECT_REJECTED("[settings]\ncapacity.contact_count = 4294967296\n", "2:26",
                    "settings.capacity.contact_count: expected an integer in [0, 4294967295], got 4294967296");
    EXPECT_REJECTED("[settings]\ncapacity.contact_count = nan\n", "2:26",
                    "settings.capacity.contact_count: expected an integer, got the number nan");
    EXPECT_REJECTED("[settings]\ncapacity.contact_count = 6e4\n", "2:26",
                    "settings.capacity.contact_count: expected an integer, got the number 60000");
    EXPECT_REJECTED("[settings]\ncapacity.contact_count = \"many\"\n", "2:26",
                    "settings.capacity.contact_count: expected an integer, got a string");
    EXPECT_REJECTED("[settings]\ncapacity = 60000\n", "2:12", "settings.capacity: expected a table");
    EXPECT_REJECTED("[settings]\ncapacity.contacts = 60000\n", "2:10", "unknown key 'contacts' in settings.capacity");
    EXPECT_REJECTED("[settings]\nmax_steps_per_frame = 2\nmin_steps_per_frame = 3\n", "3:23",
                    "expected at most max_steps_per_frame (2)");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nposition = [0, 1, 0\n", "3:21", "");  // TOML syntax
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nfriction = 1\nfriction = 2\n", "4:12",
                    "redefine");  // duplicate key
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\ntype = \"wobbly\"\n", "3:8",
                    "expected \"dynamic\", \"static\" or \"kinematic\"");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nrestitution = 2\n", "3:15", "expected a number in [0, 1]");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nrolling_resistance = -0.05\n", "3:22",
                    "body.rolling_resistance: expected a number >= 0, got -0.05");
    EXPECT_REJECTED("[defaults]\nrolling_resistance = nan\n", "2:22",
                    "defaults.rolling_resistance: expected a finite number, got nan");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\norientation = [0, 0, 0, 0]\n", "3:15", "non-zero quaternion");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\norientation = { axis = [0, 1, 0], degrees = 1, radians = 1 }\n",
                    "3:15", "exactly one of degrees or radians");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nposition = [0, nan, 0]\n", "3:16", "expected a finite number");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\ncopies = { count = [2, 0, 1], step = [1, 1, 1] }\n", "3:24",
                    "body.copies.count: expected an integer in [1, 1000000], got 0");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\ncopies = { count = [1000, 1000, 10], step = [1, 1, 1] }\n",
                    "1:1", "a scene may have at most 2000000");
    EXPECT_REJECTED("[[pyramid]]\nshape = { box = [1, 1, 1] }\n", "1:1", "pyramid: missing key 'layers'");
    EXPECT_REJECTED("[[stack]]\nshape = { sphere = 1 }\ncount = 2\ngap = 0.1\nspacing = 3\n", "5:11",
                    "stack.spacing: not allowed together with gap");
    EXPECT_REJECTED("[[body]]\ntype = \"static\"\nshape = { mesh = { vertices = [[0, 0, 0], [1, 0, 0], [0, 0, 1]], "
                    "triangles = [[0, 1, 3]] } }\n",
                    "3:86", "body.shape.mesh.triangles: expected an integer in [0, 2], got 3");
    EXPECT_REJECTED(
        "[[body]]\ntype = \"static\"\nshape = { heightfield = { size = [1, 1], heights = [[0, 0, 0], [0, 0]] } }\n",
        "3:64", "expected every row to have 3 heights, got 2");
    EXPECT_REJECTED("[[body]]\nshape = { hull = [[0, 0, 0], [1, 0, 0], [0, 1, 0]] }\n", "2:18",
                    "expected at least 4 points, got 3");
    EXPECT_REJECTED("[body]\nshape = { sphere = 1 }\n", "1:1", "body: expected [[body]] entries");
    EXPECT_REJECTED("[defaults]\nposition = [0, 0, 0]\n", "2:1", "unknown key 'position' in [defaults]");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nlock_rotation = [\"x\", \"w\"]\n", "3:23",
                    "body.lock_rotation[1]: expected \"x\", \"y\" or \"z\", got \"w\"");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nlock_translation = \"z\"\n", "3:20",
                    "body.lock_translation: expected an array of axis names");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nlock_translation = [2]\n", "3:21",
                    "body.lock_translation[0]: expected a string, got");
}

TEST(SceneParse, MissingFile_IsAClearError) {
    try {
        load_scene("/nonexistent/scene.toml");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "/nonexistent/scene.toml: cannot open scene file");
    }
}

TEST(SceneBuild, LockedBody_KeepsItsLockedAxes) {
    const SceneDesc scene = parse_scene(R"(
[[body]]
shape = { box = [0.5, 0.5, 0.5] }
position = [0, 5, 0]
velocity = [1, 0, 2]
angular_velocity = [1, 2, 3]
lock_translation = ["y", "z"]
lock_rotation = ["x", "y", "z"]
)",
                                        "locks.toml");
    Space space;
    const std::vector<BodyHandle> handles = build(scene, space);
    ASSERT_EQ(handles.size(), 1u);
    for (int step = 0; step < 30; ++step) space.update();
    const MotionState s = space.internal_motion_state(handles[0]);
    EXPECT_NEAR(s.position.x(), 0.5, 1e-12);  // moved along x alone; gravity pulls on a locked axis
    EXPECT_EQ(s.position.y(), 5.0);
    EXPECT_EQ(s.position.z(), 0.0);
    EXPECT_EQ(s.orientation.coeffs(), Quat::Identity().coeffs());
}

TEST(SceneBuild, AppliesSettings_KeepsTheSpacesTimeSteppingMode) {
    const SceneDesc scene = parse_scene(R"(
[settings]
gravity = [0, 0, -3]
substeps = 6
time_step = 0.02
sleep = false
[[body]]
shape = { sphere = 1 }
position = [0, 0, 5]
)",
                                        "s.toml");
    SpaceSettings settings;
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    const std::vector<BodyHandle> handles = build(scene, space);
    ASSERT_EQ(handles.size(), 1u);
    EXPECT_EQ(space.settings().gravity, Vec3(0, 0, -3));
    EXPECT_EQ(space.settings().solver.substeps, 6);
    EXPECT_EQ(space.settings().time_step.duration, 0.02);
    EXPECT_TRUE(space.settings().time_step.use_internal_time_stepping);
    EXPECT_FALSE(space.settings().sleep.enabled);
    EXPECT_EQ(space.internal_position(handles[0]), Vec3(0, 0, 5));
}

TEST(SceneBuild, ARejectedBody_LeavesTheSpaceAsItWas) {
    SceneDesc scene;
    scene.source = "hand.toml";
    scene.settings.gravity = Vec3(1, 2, 3);
    ShapeSpec sphere;
    sphere.type = ShapeType::Sphere;
    sphere.radius = 1;
    scene.shapes.push_back(sphere);
    SceneBody good;
    scene.bodies.push_back(good);
    SceneBody bad;
    bad.desc.mass = -1;  // the parser never makes this; create_body rejects it
    bad.line = 7;
    bad.column = 1;
    scene.bodies.push_back(bad);

    Space space;
    const std::string message = build_error(scene, space);
    EXPECT_NE(message.find("hand.toml:7:1: body: "), std::string::npos) << message;
    EXPECT_NE(message.find("mass"), std::string::npos) << message;
    EXPECT_EQ(space.body_count(), 0u);
    EXPECT_EQ(space.settings().gravity, SpaceSettings{}.gravity);
}

TEST(SceneBuild, ARejectedShape_FailsBeforeAnyBodyIsCreated) {
    SceneDesc scene;
    scene.source = "hand.toml";
    ShapeSpec broken;
    broken.type = ShapeType::Sphere;
    broken.radius = -1;  // the factory rejects it
    scene.shapes.push_back(broken);
    SceneBody body;
    body.line = 3;
    body.column = 2;
    scene.bodies.push_back(body);
    Space space;
    const std::string message = build_error(scene, space);
    EXPECT_NE(message.find("hand.toml:3:2: shape: "), std::string::npos) << message;
    EXPECT_EQ(space.body_count(), 0u);
}

}  // namespace
}  // namespace spindle

namespace spindle {

TEST(SceneParse, Chain_MakesLinksAnAnchorAndJoints) {
    const SceneDesc scene =
        parse_scene("[[chain]]\nshape = { box = [0.25, 0.1, 0.1] }\nlinks = 3\nposition = [1, 5, 0]\nend_mass = 50\n"
                    "copies = { count = [1, 1, 2], step = [0, 0, 2] }\n",
                    "chain.toml");
    ASSERT_EQ(scene.bodies.size(), 8u);  // (3 links + 1 anchor) x 2 copies
    ASSERT_EQ(scene.joints.size(), 6u);
    // First copy: links centred 0.25, 0.75, 1.25 m along x from the anchor at (1, 5, 0).
    EXPECT_NEAR(scene.bodies[0].desc.position.x(), 1.25, 1e-12);
    EXPECT_NEAR(scene.bodies[2].desc.position.x(), 2.25, 1e-12);
    EXPECT_EQ(scene.bodies[2].desc.mass, 50.0);                // the heavy end
    EXPECT_EQ(scene.bodies[3].desc.type, MotionType::Static);  // the anchor
    EXPECT_EQ(scene.joints[0].body_a, 3u);                     // anchor to first link
    EXPECT_EQ(scene.joints[0].body_b, 0u);
    EXPECT_EQ(scene.joints[2].body_a, 1u);
    EXPECT_NEAR(scene.joints[2].desc.anchors.a.x(), 2.0, 1e-12);
    EXPECT_NEAR(scene.bodies[4].desc.position.z(), 2.0, 1e-12);  // second copy
    EXPECT_EQ(scene.joints[3].body_a, 7u);
}

TEST(SceneBuild, ChainsScene_BuildsItsJoints) {
    const SceneDesc scene = load("chains");
    Space space;
    build(scene, space);
    EXPECT_EQ(space.joint_count(), scene.joints.size());
    EXPECT_GT(space.joint_count(), 50u);
    for (int i = 0; i < 30; ++i) space.update();
    EXPECT_TRUE(std::isfinite(static_cast<double>(space.state_hash())));
}

TEST(SceneParse, BrokenChains_AreRejectedAtTheLine) {
    EXPECT_REJECTED("[[chain]]\nshape = { sphere = 1 }\n", "1:1", "chain: missing key 'links'");
    EXPECT_REJECTED("[[chain]]\nshape = { sphere = 1 }\nlinks = 2\njoint = \"rope\"\n", "4:9",
                    "chain.joint: expected \"ball_socket\" or \"hinge\"");
    EXPECT_REJECTED("[[chain]]\nshape = { sphere = 1 }\nlinks = 2\ndirection = [0, 0, 0]\n", "4:13",
                    "chain.direction: expected a non-zero vector");
    EXPECT_REJECTED("[[chain]]\ntype = \"static\"\nshape = { sphere = 1 }\nlinks = 2\n", "1:1",
                    "chain links must be dynamic");
}

TEST(SceneParse, FilterKeys_LayerGroupAndIgnoredLayerPairs) {
    const SceneDesc scene = parse_scene("[settings]\nignore_layers = [[1, 2], [3, 3]]\n"
                                        "[defaults]\nlayer = 4\n"
                                        "[[body]]\nshape = { sphere = 1 }\nlayer = 1\ngroup = 7\n"
                                        "[[body]]\nshape = { sphere = 1 }\n",
                                        "filters.toml");
    ASSERT_EQ(scene.ignore_layers.size(), 2u);
    EXPECT_EQ(scene.ignore_layers[0], (std::array<std::uint32_t, 2>{1, 2}));
    EXPECT_EQ(scene.ignore_layers[1], (std::array<std::uint32_t, 2>{3, 3}));
    ASSERT_EQ(scene.bodies.size(), 2u);
    EXPECT_EQ(scene.bodies[0].desc.layer, 1u);
    EXPECT_EQ(scene.bodies[0].desc.group, 7u);
    EXPECT_EQ(scene.bodies[1].desc.layer, 4u);  // from [defaults]
    EXPECT_EQ(scene.bodies[1].desc.group, 0u);

    Space space;
    const std::vector<BodyHandle> bodies = build(scene, space);
    EXPECT_FALSE(space.layers_collide(1, 2));
    EXPECT_FALSE(space.layers_collide(2, 1));
    EXPECT_FALSE(space.layers_collide(3, 3));
    EXPECT_TRUE(space.layers_collide(1, 3));
    EXPECT_EQ(space.internal_desc(bodies[0]).layer, 1u);
    EXPECT_EQ(space.internal_desc(bodies[0]).group, 7u);
}

TEST(SceneParse, BadFilterKeys_AreRejectedAtTheLine) {
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nlayer = 32\n", "3:9",
                    "body.layer: expected an integer in [0, 31], got 32");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\ngroup = -1\n", "3:9", "body.group: expected an integer");
    EXPECT_REJECTED("[settings]\nignore_layers = [[1, 40]]\n", "2:22",
                    "settings.ignore_layers[0][1]: expected an integer in [0, 31], got 40");
    EXPECT_REJECTED("[settings]\nignore_layers = [[1]]\n", "2:18", "settings.ignore_layers[0]: expected two layers");
    EXPECT_REJECTED("[settings]\nignore_layers = [1, 2]\n", "2:18", "settings.ignore_layers[0]: expected an array");
}

TEST(SceneParse, EventKeys_ContactEventsAndSensor) {
    const SceneDesc scene = parse_scene("[defaults]\ncontact_events = true\n"
                                        "[[body]]\nshape = { sphere = 1 }\nsensor = true\n"
                                        "[[body]]\nshape = { sphere = 1 }\ncontact_events = false\n",
                                        "events.toml");
    ASSERT_EQ(scene.bodies.size(), 2u);
    EXPECT_TRUE(scene.bodies[0].desc.contact_events);  // from [defaults]
    EXPECT_TRUE(scene.bodies[0].desc.sensor);
    EXPECT_FALSE(scene.bodies[1].desc.contact_events);
    EXPECT_FALSE(scene.bodies[1].desc.sensor);
    Space space;
    const std::vector<BodyHandle> bodies = build(scene, space);
    EXPECT_TRUE(space.internal_desc(bodies[0]).sensor);
    EXPECT_TRUE(space.internal_desc(bodies[0]).contact_events);
}

TEST(SceneParse, BadEventKeys_AreRejectedAtTheLine) {
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\nsensor = 1\n", "3:10",
                    "body.sensor: expected true or false, got the integer 1");
    EXPECT_REJECTED("[[body]]\nshape = { sphere = 1 }\ncontact_events = \"yes\"\n", "3:18",
                    "body.contact_events: expected true or false");
}

TEST(SceneBuild, ARejectedBody_RestoresTheLayerTable) {
    SceneDesc scene = parse_scene("[settings]\nignore_layers = [[1, 2]]\n[[body]]\nshape = { sphere = 1 }\n",
                                  "hand.toml");
    scene.bodies[0].desc.mass = -1;  // the parser never makes this; create_body rejects it
    Space space;
    EXPECT_NE(build_error(scene, space).find("mass"), std::string::npos);
    EXPECT_TRUE(space.layers_collide(1, 2));
}

}  // namespace spindle
