// Built by the install test against an installed Spindle: a scene file's text through
// spindle::scene into a Space.
#include <spindle/engine/space.hpp>
#include <spindle/scene/scene.hpp>

#include <cstdio>

int main() {
    const char* text = R"(
name = "drop"
[[body]]
shape = { sphere = 0.5 }
position = [0, 10, 0]
)";
    spindle::Space space;
    const auto bodies = spindle::build(spindle::parse_scene(text, "drop.toml"), space);
    for (int i = 0; i < 60; ++i) space.update();
    std::printf("scene bodies: %zu, y after 1 s: %.3f\n", bodies.size(), space.internal_position(bodies[0]).y());
}
