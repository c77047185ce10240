// SpaceInternals: the live World behind a Space, for the engine's own tests and
// benchmarks (through the unexported spindle_engine_internal target); a game never
// includes it.
#pragma once

#include <spindle/engine/space.hpp>

#include "world.hpp"

namespace spindle {

struct SpaceInternals {
    static World& world(Space& space) noexcept { return *space.m_world; }
    static const World& world(const Space& space) noexcept { return *space.m_world; }
};

}  // namespace spindle
