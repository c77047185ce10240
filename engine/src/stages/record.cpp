// Record stage: previous <- current for the bodies that interpolate, so the flip can
// publish the last two steps for blending. Bodies without the flag pay nothing.
#include "stages/stages.hpp"

namespace spindle {

void record(World& world) {
    if (!world.settings.time_step.use_internal_time_stepping) return;
    Bodies& b = world.bodies;
    for (std::uint32_t i : world.awake) {
        if (!b.interpolate[i]) continue;
        const std::uint32_t h = b.history_place[i];  // an awake body can move: it has one
        b.history_position[0][h] = b.history_position[1][h];
        b.history_orientation[0][h] = b.history_orientation[1][h];
        b.history_position[1][h] = b.origin(i);
        b.history_orientation[1][h] = b.q[i];
    }
}

}  // namespace spindle
