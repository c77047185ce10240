// Scenes from TOML files (docs/scenes.md): settings, bodies and generators parsed into
// a SceneDesc, then built into a Space. Every error names file:line:column.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <spindle/engine/body.hpp>
#include <spindle/engine/joint.hpp>
#include <spindle/engine/settings.hpp>

namespace spindle {

class Space;

// A shape as the file describes it. Kept apart from Shape so that a scene can be parsed
// (and checked) without building the geometry: build() calls the factories once per
// ShapeSpec and every body made from it shares the result.
struct CompoundPartSpec;

struct ShapeSpec {
    ShapeType type = ShapeType::Sphere;
    Real radius = 0;                      // sphere, capsule (m)
    Real half_height = 0;                 // capsule (m)
    Vec3 half_extents = Vec3::Zero();     // box (m)
    Vec3 normal = Vec3::UnitY();          // plane
    Real offset = 0;                      // plane (m)
    std::vector<Vec3> points;             // hull points, or mesh vertices (m, body frame)
    std::vector<std::uint32_t> indices;   // mesh: 3 per triangle, counter-clockwise from the front
    std::vector<CompoundPartSpec> parts;  // compound: convex parts posed in the body's frame

    // Calls the Shape factory. Throws spindle::Error when the factory rejects it.
    Shape make() const;
    // Half the size of the shape's bounds under orientation q (generators space bodies
    // by it); zero for static-only shapes (plane, mesh).
    Vec3 half_size(const Quat& q) const;
};

struct CompoundPartSpec {
    ShapeSpec shape;
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
};

// One body of the scene. desc holds everything but the shape: build() fills
// desc.shape from shapes[shape].
struct SceneBody {
    BodyDesc desc;
    std::uint32_t shape = 0;  // index into SceneDesc::shapes
    std::uint32_t line = 0;   // where the entry that made this body starts in the file
    std::uint32_t column = 0;
};

// A joint between two scene bodies (indices into SceneDesc::bodies). desc holds its kind,
// anchor, axes and limits in the World frame; build() fills in desc.body_a and body_b.
struct SceneJoint {
    JointDesc desc;
    std::uint32_t body_a = 0, body_b = 0;
    std::uint32_t line = 0, column = 0;  // where the entry that made this joint starts
};

struct SceneDesc {
    std::string name;  // the file's `name`, else its file name without .toml
    std::string description;
    std::string source;      // file name (or the name it was parsed under)
    SpaceSettings settings;  // time_step.use_internal_time_stepping is left to the program
    // [settings] ignore_layers: pairs of layers that do not collide (the rest do).
    std::vector<std::array<std::uint32_t, 2>> ignore_layers;
    std::vector<ShapeSpec> shapes;
    std::vector<SceneBody> bodies;   // generators expanded, in file order
    std::vector<SceneJoint> joints;  // made by [[chain]] and [[ragdoll]]; created after the bodies

    std::size_t dynamic_body_count() const noexcept;
};

// Parses a scene. Unknown keys, wrong types and bad values throw spindle::Error
// "source:line:column: what was expected". Nothing is built.
SceneDesc parse_scene(std::string_view toml_text, std::string_view source_name);
// Reads and parses a file; "path: cannot open scene file" when it cannot be read.
SceneDesc load_scene(const std::string& path);

// Applies the scene's settings (gravity, time step duration and caps, solver, sleep, the
// ignored layer pairs; the space's use_internal_time_stepping is kept) and creates its bodies, in scene
// order, then its joints. Returns the bodies' handles, one per SceneDesc::bodies entry, and,
// when `joints` is given, the joints' handles in it, one per SceneDesc::joints entry. Every shape is made
// before any body is created; if anything is rejected the bodies created so far are
// destroyed again, the settings restored, and the spindle::Error names the entry's
// file:line:column.
// Who may call: the thread that updates the space, while no update runs.
std::vector<BodyHandle> build(const SceneDesc& scene, Space& space, std::vector<JointHandle>* joints = nullptr);

}  // namespace spindle
