// Contact events read by the game thread while an AsyncRunner steps the space: every
// event of every step arrives once, in order, whatever the updates and reads interleave
// (the TSan build checks the events' queue for races).
#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include "async_util.hpp"
#include "static_bodies.hpp"

#include <chrono>
#include <thread>
#include <vector>

using namespace spindle;
using namespace spindle::test;

namespace {

// Many short steps so that a short run has many: balls bouncing on the ground and on
// each other begin, end and hit all the time.
SpaceSettings bouncing_settings() {
    SpaceSettings s;
    s.time_step.duration = 1.0 / 240.0;
    s.time_step.use_internal_time_stepping = true;
    return s;
}

void add_bouncing_balls(Space& space) {
    test::add_static_box(space, Vec3(10, 0.5, 10), Vec3(0, -0.5, 0));
    for (int i = 0; i < 24; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.position = Vec3(0.7 * (i % 6) - 1.75 + 0.13 * (i / 6), 0.7 + 0.9 * (i / 6), 0.3 * (i % 3));
        d.restitution = 0.8;
        d.contact_events = true;
        space.create_body(d);
    }
}

bool same(const ContactEvent& x, const ContactEvent& y) {
    return x.kind == y.kind && x.body_a == y.body_a && x.body_b == y.body_b && x.step == y.step && x.point == y.point &&
           x.normal == y.normal && x.speed == y.speed;
}

}  // namespace

TEST(ContactEventsAsync, GameThreadReadsEveryEventOnceWhileTheRunnerSteps) {
    Space space(bouncing_settings());
    add_bouncing_balls(space);
    AsyncRunner runner(space);
    std::vector<ContactEvent> seen, batch;
    std::size_t reads = 0;
    finishes_in_time([&] {
        runner.start();
        const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(600);
        // Reads at once, and after pauses spanning none to several flips (a step is 4 ms),
        // for 600 ms, until the loop published 20 steps and until two reads found events:
        // stacked balls touch from the first step and land at about the 48th (0.2 m to fall),
        // so a runner slowed by load may publish 20 steps with one burst of events. A loaded
        // machine only takes longer (finishes_in_time bounds a hang).
        constexpr int kPauseMicroseconds[] = {0, 300, 1000, 5000, 12000};
        for (int i = 0;
             std::chrono::steady_clock::now() < end || space.motion_states().published_steps() <= 20 || reads < 2;
             ++i) {
            batch.clear();
            reads += space.read_contact_events(batch) > 0 ? 1 : 0;
            seen.insert(seen.end(), batch.begin(), batch.end());
            std::this_thread::sleep_for(std::chrono::microseconds(kPauseMicroseconds[i % 5]));
        }
        runner.stop();
    });
    space.read_contact_events(seen);  // what the last updates published
    const std::uint64_t steps = space.counters().steps;
    ASSERT_GT(steps, 20u);
    EXPECT_EQ(space.dropped_contact_events(), 0u);

    // The same steps taken one per update, read after each: the sequence the game must have seen.
    Space reference(bouncing_settings());
    add_bouncing_balls(reference);
    std::vector<ContactEvent> expected;
    for (std::uint64_t s = 0; s < steps; ++s) {
        reference.update();
        reference.read_contact_events(expected);
    }
    ASSERT_GT(expected.size(), 20u);
    ASSERT_EQ(seen.size(), expected.size()) << reads << " reads over " << steps << " steps";
    for (std::size_t k = 0; k < seen.size(); ++k) ASSERT_TRUE(same(seen[k], expected[k])) << "event " << k;
    EXPECT_GT(reads, 1u);  // read while it ran, not only at the end
}
