// Benchmark scenes: the box scenes both engines build, and the Spindle-only mixed pile on
// a mesh and chain pile. Positions are computed, never random, so every run builds the
// same scene.
#include "common/scenes.hpp"

#include <cmath>
#include <cstdint>

namespace spindle::bench {

namespace {

// Coordinate of item `index` of `count` laid out `pitch` apart, centred on 0.
Real centered(int index, int count, Real pitch) { return (index - (count - 1) / 2.0) * pitch; }

// A scene with no boxes yet, over a 2 m thick floor box whose top face is y = 0.
BoxScene on_floor(const char* name, Real half_x, Real half_z, Real friction) {
    BoxScene scene;
    scene.name = name;
    scene.floor = {Vec3(0, -1, 0), Vec3(half_x, 1, half_z)};
    scene.friction = friction;
    return scene;
}

}  // namespace

BoxScene pyramid_scene() {
    BoxScene scene = on_floor("pyramid", 50, 50, 0.2);
    constexpr int kLayers = 15;
    for (int i = 0; i < kLayers; ++i) {
        const Real h = (i % 2 == 1) ? 1 : 0;  // odd layers sit in the hollows of the one below
        for (int j = i / 2; j < kLayers - (i + 1) / 2; ++j) {
            for (int k = i / 2; k < kLayers - (i + 1) / 2; ++k) {
                scene.boxes.push_back({Vec3(-15 + 2 * j + h, 1 + 2.5 * i, -15 + 2 * k + h), Vec3::Ones()});
            }
        }
    }
    return scene;
}

BoxScene many_pyramids_scene() {
    constexpr int kPerSide = 14;
    constexpr int kBase = 10;
    constexpr Real kHalf = 0.5;
    constexpr Real kPitchX = kBase * 2 * kHalf + 2;  // 2 m between neighbouring bases
    constexpr Real kPitchZ = 2 * kHalf + 2;
    BoxScene scene = on_floor("many_pyramids", kPerSide * kPitchX / 2 + 5, kPerSide * kPitchZ / 2 + 5, 0.6);
    for (int px = 0; px < kPerSide; ++px) {
        for (int pz = 0; pz < kPerSide; ++pz) {
            const Vec3 base(centered(px, kPerSide, kPitchX), kHalf, centered(pz, kPerSide, kPitchZ));
            for (int layer = 0; layer < kBase; ++layer) {
                // Layer `layer` holds kBase - layer boxes, centred over the base like the one below.
                for (int j = 0; j < kBase - layer; ++j) {
                    const Vec3 offset(centered(j, kBase - layer, 2 * kHalf), 2 * kHalf * layer, 0);
                    scene.boxes.push_back({base + offset, Vec3::Constant(kHalf)});
                }
            }
        }
    }
    return scene;
}

BoxScene box_grid_scene(int per_side) {
    constexpr Real kHalf = 0.5;
    constexpr Real kPitch = 1.5;  // 0.5 m gaps: every box is its own island
    const Real half_floor = per_side * kPitch / 2 + 5;
    BoxScene scene = on_floor("box_grid", half_floor, half_floor, 0.6);
    for (int a = 0; a < per_side; ++a) {
        for (int b = 0; b < per_side; ++b) {
            scene.boxes.push_back(
                {Vec3(centered(a, per_side, kPitch), kHalf, centered(b, per_side, kPitch)), Vec3::Constant(kHalf)});
        }
    }
    return scene;
}

std::vector<BodyHandle> add_to_space(Space& space, const BoxScene& scene, const BuildOptions& options) {
    // Room for the floor and the boxes first, as the scene loader's build() asks for its
    // bodies: the per-body arrays are made once, at their size, not grown as they come.
    space.reserve_bodies(space.body_count() + 1 + scene.boxes.size());
    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.friction = scene.friction;
    if (options.floor == FloorShape::Box) {
        floor.shape = Shape::box(scene.floor.half_extents);
        floor.position = scene.floor.center;
    } else {
        const Real top = scene.floor.center.y() + scene.floor.half_extents.y();
        floor.shape = Shape::plane(Vec3::UnitY(), top);
    }
    space.create_body(floor);

    std::vector<BodyHandle> handles;
    handles.reserve(scene.boxes.size());
    BodyDesc box;
    box.friction = scene.friction;
    box.density = scene.density;
    box.allow_sleep = options.allow_sleep;
    box.contact_events = options.contact_events;
    box.allow_interpolation = false;  // benches read internal state; nothing to blend
    for (const BoxSpec& spec : scene.boxes) {
        box.shape = Shape::box(spec.half_extents);  // shapes are values: one per body, as a user would
        box.position = spec.center;
        handles.push_back(space.create_body(box));
    }
    return handles;
}

namespace {

// Rolling terrain: two crossed waves, at most ~1.3 m high.
Real terrain_height(Real x, Real z) {
    return std::sin(0.15 * x) * std::cos(0.12 * z) + 0.3 * std::sin(0.5 * x + 0.3 * z);
}

Shape terrain_mesh(int cells, Real cell_size) {
    const int n = cells + 1;
    const Real origin = -cells * cell_size / 2;
    std::vector<Vec3> vertices;
    vertices.reserve(static_cast<std::size_t>(n * n));
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const Real x = origin + i * cell_size;
            const Real z = origin + j * cell_size;
            vertices.emplace_back(x, terrain_height(x, z), z);
        }
    }
    std::vector<std::uint32_t> indices;
    indices.reserve(static_cast<std::size_t>(cells * cells * 6));
    auto at = [n](int i, int j) { return static_cast<std::uint32_t>(i * n + j); };
    for (int i = 0; i < cells; ++i) {
        for (int j = 0; j < cells; ++j) {
            // Counter-clockwise seen from above (x right, z toward the viewer): normals point up.
            const std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            indices.insert(indices.end(), {a, d, b, b, d, c});
        }
    }
    return Shape::triangle_mesh(vertices, indices);
}

// An irregular 10-point rock, about 1 m across.
Shape rock_hull() {
    const Vec3 points[] = {{0.5, 0, 0},       {-0.45, 0.05, 0},   {0, 0.35, 0.1},    {0.05, -0.3, 0},
                           {0, 0, 0.4},       {0.1, 0, -0.45},    {0.3, 0.25, 0.25}, {-0.3, -0.2, 0.2},
                           {-0.2, 0.2, -0.3}, {0.25, -0.2, -0.25}};
    return Shape::convex_hull(points);
}

}  // namespace

std::vector<BodyHandle> add_mixed_pile_on_mesh(Space& space, int count) {
    constexpr int kCells = 40;
    constexpr Real kCell = 2.0;  // 80 m square of terrain
    constexpr int kPerRow = 16;  // bodies per row and per column of a drop layer
    constexpr Real kPitch = 2.0;
    BodyDesc ground;
    ground.type = MotionType::Static;
    ground.shape = terrain_mesh(kCells, kCell);
    ground.friction = 0.6;
    space.create_body(ground);

    const Shape shapes[] = {Shape::sphere(0.5), Shape::box(Vec3(0.4, 0.5, 0.6)), Shape::capsule(0.4, 0.35),
                            rock_hull()};
    std::vector<BodyHandle> handles;
    handles.reserve(static_cast<std::size_t>(count));
    BodyDesc body;
    body.friction = 0.6;
    body.allow_interpolation = false;
    for (int n = 0; n < count; ++n) {
        const int layer = n / (kPerRow * kPerRow);
        const int a = (n / kPerRow) % kPerRow;
        const int b = n % kPerRow;
        body.shape = shapes[n % 4];
        // Odd layers shifted by half a pitch, so the pile does not fall in columns.
        const Real shift = (layer % 2) * kPitch / 2;
        body.position = Vec3(centered(a, kPerRow, kPitch) + shift, 4 + 2 * layer, centered(b, kPerRow, kPitch) + shift);
        body.orientation = Quat(Eigen::AngleAxis<Real>(0.7 * n, Vec3(1, 0.5 * (n % 3), 0.3).normalized()));
        handles.push_back(space.create_body(body));
    }
    return handles;
}

std::vector<BodyHandle> add_chain_pile(Space& space, int chains, int links) {
    constexpr Real kHalfHeight = 0.25;  // capsule links 0.7 m tip to tip, 0.2 m thick
    constexpr Real kRadius = 0.1;
    constexpr Real kLinkLength = 2 * (kHalfHeight + kRadius);  // centre to centre: tips touch
    constexpr int kChainsPerLayer = 10;
    constexpr Real kChainPitch = 0.7;    // side by side in a layer: 0.5 m gaps to fall through
    constexpr Real kLayerPitch = 0.5;    // vertical: 0.3 m gaps, so no body starts in contact
    constexpr Real kBottomHeight = 1.0;  // the bottom layer falls too
    // Each layer turned ~63 degrees from the one below: links cross at varied angles and
    // slide off each other, rather than stacking into a square woodpile that stays ordered.
    constexpr Real kLayerTurn = 1.1;  // rad

    BodyDesc floor;
    floor.type = MotionType::Static;
    floor.shape = Shape::box(Vec3(20, 1, 20));  // top face at y = 0, well beyond the pile
    floor.position = Vec3(0, -1, 0);
    space.create_body(floor);

    BodyDesc link;
    link.shape = Shape::capsule(kHalfHeight, kRadius);
    link.allow_interpolation = false;
    std::vector<BodyHandle> handles;
    handles.reserve(static_cast<std::size_t>(chains * links));
    for (int c = 0; c < chains; ++c) {
        const int layer = c / kChainsPerLayer;
        const Real angle = kLayerTurn * layer;
        const Vec3 along(std::cos(angle), 0, std::sin(angle));  // the chain's direction
        const Vec3 across(-along.z(), 0, along.x());
        const Vec3 center = across * centered(c % kChainsPerLayer, kChainsPerLayer, kChainPitch) +
                            Vec3(0, kBottomHeight + kLayerPitch * layer, 0);
        const Vec3 first_tip = center - along * (kLinkLength * links / 2);
        link.orientation = Quat::FromTwoVectors(Vec3::UnitY(), along);  // capsules are built along y
        for (int i = 0; i < links; ++i) {
            link.position = first_tip + along * (kLinkLength * (i + 0.5));
            const BodyHandle body = space.create_body(link);
            if (i > 0) {
                const Vec3 touching_tips = first_tip + along * (kLinkLength * i);
                space.create_joint(JointDesc::ball_socket_at(handles.back(), body, touching_tips));
            }
            handles.push_back(body);
        }
    }
    return handles;
}

Real height_of(const Space& space, BodyHandle body) { return space.internal_position(body).y(); }

}  // namespace spindle::bench
