// What `spindle view` sends its page: the scene description when the set of bodies
// changes (JSON: every shape's type and size, hull and mesh points; each body's shape),
// and every frame only poses (binary, below), so a frame of n bodies is 32n bytes.
//
// Frame, little-endian:
//   u32 magic "SPVF", u32 scene version, u32 bodies, u32 contact marks, u32 flags, u32 0,
//   f64 simulated seconds, f64 steps published,
//   per body (scene order):  f32 px py pz qx qy qz qw asleep(0|1)
//   per contact mark:        f32 px py pz nx ny nz age(s)
// A frame whose scene version is not the page's tells it to fetch the scene again.
// Scene JSON: {"version", "name", "shapes": [{type, radius, half_height, half_extents,
// normal, offset, points, indices}], "bodies": [[shape, moving, projectile, sensor]]}.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <spindle/engine/body.hpp>
#include <spindle/scene/scene.hpp>

namespace spindle::app {

inline constexpr std::uint32_t kFrameMagic = 0x46565053;  // "SPVF" read as little-endian bytes

// A body as the page draws it.
struct ViewBody {
    std::uint32_t shape = 0;  // index into the shapes sent with it
    bool moving = false;      // not static: drawn solid, can sleep
    bool projectile = false;  // shot from the page
    bool sensor = false;      // an overlap volume, not a solid: drawn see-through
};

enum FrameFlags : std::uint32_t {
    kFramePaused = 1u << 0,
    kFrameInterpolated = 1u << 1,
    kFrameReplay = 1u << 2,
    kFrameSlow = 1u << 3,
};

struct FrameHeader {
    std::uint32_t scene_version = 0;
    std::uint32_t flags = 0;
    double simulated_seconds = 0;
    double steps = 0;
};

// A contact the page marks: a hit event for a moment (where, its normal, how old), or
// a touching point of the newest step (age 0) while the page asks for them.
struct ContactMark {
    Vec3 point = Vec3::Zero();
    Vec3 normal = Vec3::UnitY();
    double age = 0;
};

std::string scene_json(std::uint32_t version, std::string_view name, std::span<const ShapeSpec> shapes,
                       std::span<const ViewBody> bodies);

// states and asleep have one entry per body (asleep may be empty: none asleep).
std::string encode_frame(const FrameHeader& header, std::span<const MotionState> states,
                         std::span<const std::uint8_t> asleep, std::span<const ContactMark> contacts);

// text as a JSON string literal, quotes included.
std::string json_string(std::string_view text);

}  // namespace spindle::app
