// Building a parsed scene into a Space: settings, shapes made once and shared, bodies
// in scene order; all or nothing.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/scene/scene.hpp>

#include <array>
#include <utility>
#include <vector>

namespace spindle {
namespace {

[[noreturn]] void fail_at(const SceneDesc& scene, const SceneBody& body, const char* what, const Error& error) {
    throw Error(scene.source + ":" + std::to_string(body.line) + ":" + std::to_string(body.column) + ": " + what +
                ": " + error.what());
}

}  // namespace

std::vector<BodyHandle> build(const SceneDesc& scene, Space& space, std::vector<JointHandle>* joints) {
    // Shapes first: a factory that rejects one (or does not exist yet) fails before
    // anything in the space has changed. Each is made once and shared by its bodies.
    std::vector<Shape> shapes;
    shapes.reserve(scene.shapes.size());
    for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
        try {
            shapes.push_back(scene.shapes[i].make());
        } catch (const Error& e) {
            for (const SceneBody& body : scene.bodies) {
                if (body.shape == i) fail_at(scene, body, "shape", e);
            }
            throw Error(scene.source + ": shape: " + e.what());  // a [defaults] shape no body uses
        }
    }

    // Room for every body at once (before anything changes: it may throw): a million-body
    // scene's per-body arrays would otherwise be moved dozens of times as they grow.
    space.reserve_bodies(space.body_count() + scene.bodies.size());

    const SpaceSettings before = space.settings();
    // The layer pairs the scene turns off, with whether each collided before, to restore.
    std::vector<std::pair<std::array<std::uint32_t, 2>, bool>> layers_before;
    for (const auto& pair : scene.ignore_layers) {
        layers_before.emplace_back(pair, space.layers_collide(pair[0], pair[1]));
    }
    auto restore = [&] {
        space.set_time_step(before.time_step);
        space.set_solver(before.solver);
        space.set_sleep(before.sleep);
        space.set_gravity(before.gravity);
        for (auto it = layers_before.rbegin(); it != layers_before.rend(); ++it) {
            space.set_layers_collide(it->first[0], it->first[1], it->second);
        }
    };
    TimeStepSettings time_step = scene.settings.time_step;
    time_step.use_internal_time_stepping = space.settings().time_step.use_internal_time_stepping;
    space.set_time_step(time_step);
    space.set_solver(scene.settings.solver);
    space.set_sleep(scene.settings.sleep);
    space.set_gravity(scene.settings.gravity);
    for (const auto& pair : scene.ignore_layers) space.set_layers_collide(pair[0], pair[1], false);

    std::vector<BodyHandle> handles;
    handles.reserve(scene.bodies.size());
    for (const SceneBody& body : scene.bodies) {
        BodyDesc desc = body.desc;
        desc.shape = shapes[body.shape];
        try {
            handles.push_back(space.create_body(desc));
        } catch (const Error& e) {
            for (auto it = handles.rbegin(); it != handles.rend(); ++it) space.destroy_body(*it);
            restore();
            fail_at(scene, body, "body", e);
        }
    }
    std::vector<JointHandle> joint_handles;
    joint_handles.reserve(scene.joints.size());
    for (const SceneJoint& joint : scene.joints) {
        JointDesc desc = joint.desc;
        desc.body_a = handles[joint.body_a];
        desc.body_b = handles[joint.body_b];
        try {
            joint_handles.push_back(space.create_joint(desc));
        } catch (const Error& e) {
            // Destroying the bodies destroys the joints made so far with them.
            for (auto it = handles.rbegin(); it != handles.rend(); ++it) space.destroy_body(*it);
            restore();
            throw Error(scene.source + ":" + std::to_string(joint.line) + ":" + std::to_string(joint.column) +
                        ": joint: " + e.what());
        }
    }
    if (joints) *joints = std::move(joint_handles);
    return handles;
}

}  // namespace spindle
