// Benchmark scenes shared by bench_peers and bench_engine: engine-neutral box scenes
// (so Bullet and Spindle build the same thing) and builders that put scenes into a Space.
#pragma once

#include <span>
#include <string>
#include <vector>

#include <spindle/engine/space.hpp>

namespace spindle::bench {

struct BoxSpec {
    Vec3 center = Vec3::Zero();
    Vec3 half_extents = Vec3::Ones();
};

// Dynamic boxes (axis aligned at rest) over one static floor box: what every peer can build.
struct BoxScene {
    std::string name;
    BoxSpec floor;
    std::vector<BoxSpec> boxes;  // the last one is the "top" box a stacking check follows
    Real friction = 0.2;         // every body, the floor too: pairs mix to this value
    Real density = 1000;         // kg/m^3
};

// Jolt PerformanceTest's "Pyramid": floor box (50, 1, 50) at (0, -1, 0); 15 layers of cubes
// of half extent 1 with 0.5 m gaps between layers; 1240 boxes; friction 0.2. Standing, the
// top box's centre is at about 28.99.
BoxScene pyramid_scene();

// 14 x 14 two-dimensional pyramids (walls in the x-y plane) of base 10, 55 cubes of half
// extent 0.5 each, layers touching; 10,780 boxes, 2 m apart so pyramids never touch.
BoxScene many_pyramids_scene();

// per_side^2 cubes of half extent 0.5 resting (not touching each other) on a floor.
BoxScene box_grid_scene(int per_side);

enum class FloorShape {
    Box,    // the scene's floor box: the real scene
    Plane,  // a static plane at the floor's top face: a smoke check for narrowphases without box-box
};

struct BuildOptions {
    FloorShape floor = FloorShape::Box;
    bool allow_sleep = true;
    bool contact_events = false;  // every box asks for contact events
};

// Creates the scene's bodies; returns the dynamic boxes' handles in scene order.
std::vector<BodyHandle> add_to_space(Space& space, const BoxScene& scene, const BuildOptions& options = {});

// Spheres, boxes, capsules and convex hulls (count in all, cycling through the four)
// dropped from a grid onto a static rolling-terrain triangle mesh; returns their handles.
std::vector<BodyHandle> add_mixed_pile_on_mesh(Space& space, int count);

// `chains` free chains of `links` capsule links each, ball-socket jointed where neighbouring
// links touch, dropped in layers of 10 parallel chains (each layer turned against the one
// below) onto a static floor box, to fall and tangle into a pile; returns the links' handles,
// chain by chain.
std::vector<BodyHandle> add_chain_pile(Space& space, int chains, int links);

// Height of a body's position (internal state: the update thread, between updates).
Real height_of(const Space& space, BodyHandle body);

}  // namespace spindle::bench
