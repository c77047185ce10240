// Built by the install test against an installed Spindle.
#include <cstdio>
#include <spindle/engine/space.hpp>
int main() {
    spindle::Space space;
    spindle::BodyDesc d;
    d.position = {0, 10, 0};
    auto h = space.create_body(d);
    for (int i = 0; i < 60; ++i) space.update();
    std::printf("y after 1 s: %.3f\n", space.internal_position(h).y());
}
