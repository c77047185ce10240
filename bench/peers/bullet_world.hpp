// BulletBoxWorld: a BoxScene built in Bullet 3 (btDiscreteDynamicsWorld). Bullet's headers
// stay in bullet_world.cpp, so only that file needs them.
#pragma once

#include <cstddef>
#include <memory>

#include "common/scenes.hpp"

namespace spindle::bench {

class BulletBoxWorld {
public:
    // Gravity -9.81, every body the scene's friction, pairs mixed as the geometric mean (as
    // Spindle and Jolt do; Bullet's default is the product), boxes never deactivate.
    explicit BulletBoxWorld(const BoxScene& scene);
    ~BulletBoxWorld();
    BulletBoxWorld(const BulletBoxWorld&) = delete;
    BulletBoxWorld& operator=(const BulletBoxWorld&) = delete;

    // One plain 60 Hz step: stepSimulation(1/60, 0) takes exactly one internal step of
    // 1/60 s (no substeps, no interpolation), like Spindle's update() without internal stepping.
    void step();
    // Centre height of dynamic box i (scene order).
    double height(std::size_t box) const;
    std::size_t box_count() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace spindle::bench
