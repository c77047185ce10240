// Calls on a space the suites share: stepping it, the error a call throws, settings
// without gravity.
#pragma once

#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>

#include <string>

namespace spindle::test {

inline void run(Space& space, int steps) {
    for (int i = 0; i < steps; ++i) space.update();
}

// The message of the Error the call throws, or "(no error)".
std::string error_of(auto&& call) {
    try {
        call();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

inline SpaceSettings weightless() {
    SpaceSettings s;
    s.gravity = Vec3::Zero();
    return s;
}

}  // namespace spindle::test
