// Contact events: Begin once when bodies start touching and End when they stop or their
// contact goes (lifted, destroyed, filtered), Hit with the impact speed, nothing and no
// work for bodies that did not ask, none lost or repeated however updates and reads fall,
// a bounded queue, and the same sequence for any worker count.
#include <spindle/engine/space.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/single_threaded.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "events_common.hpp"

using namespace spindle;
using namespace spindle::test;

namespace events_test {

namespace {

// A ball dropped 1.5 m onto the ground, run until it has rested a while (it falls asleep).
struct Landing {
    Space space;
    BodyHandle ground, ball;
    explicit Landing(const SpaceSettings& settings = {}) : space(settings) {
        ground = add_ground(space);
        ball = space.create_body(spindle::test::ball(1.5));
    }
};

}  // namespace

TEST(ContactEvents, BallLanding_BeginsOnce_NoDuplicateWhileResting) {
    Landing scene;
    run(scene.space, 240);  // lands within 40 steps, then rests and falls asleep
    EXPECT_FALSE(scene.space.internal_is_awake(scene.ball));
    const std::vector<ContactEvent> events = read_all(scene.space);
    ASSERT_EQ(count(events, ContactEventKind::Begin), 1u);
    EXPECT_EQ(count(events, ContactEventKind::End), 0u);  // asleep, still touching
    EXPECT_EQ(count(events, ContactEventKind::Hit), 1u);  // the landing; resting pushes are no hits
    const ContactEvent& begin = *std::find_if(events.begin(), events.end(),
                                              [](const ContactEvent& e) { return e.kind == ContactEventKind::Begin; });
    EXPECT_EQ(begin.body_a, scene.ground);  // the lower slot first
    EXPECT_EQ(begin.body_b, scene.ball);
    EXPECT_FALSE(begin.sensor);
    // t = sqrt(2 h / g) = 0.553 s: step 33 or 34 at 60 Hz (the bottom reaches the ground then).
    EXPECT_GE(begin.step, 32u);
    EXPECT_LE(begin.step, 35u);
    // Asleep and woken again, still touching: no new Begin.
    scene.space.wake(scene.ball);
    run(scene.space, 30);
    EXPECT_EQ(read_all(scene.space).size(), 0u);
}

TEST(ContactEvents, LiftedAway_Ends) {
    Landing scene;
    run(scene.space, 60);
    ASSERT_EQ(count(read_all(scene.space), ContactEventKind::Begin), 1u);
    scene.space.set_position(scene.ball, Vec3(0, 5, 0));
    run(scene.space, 2);
    const std::vector<ContactEvent> events = read_all(scene.space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
    EXPECT_EQ(events[0].body_b, scene.ball);
    EXPECT_EQ(events[0].step, 61u);  // the step after the teleport
    // It falls back: a second Begin.
    run(scene.space, 90);
    EXPECT_EQ(count(read_all(scene.space), ContactEventKind::Begin), 1u);
}

TEST(ContactEvents, DestroyingATouchingBody_Ends) {
    Landing scene;
    run(scene.space, 60);
    ASSERT_EQ(read_all(scene.space).size(), 2u);  // Begin, Hit
    scene.space.destroy_body(scene.ball);
    EXPECT_EQ(read_all(scene.space).size(), 0u);  // published by the next flip, not before
    scene.space.update();
    const std::vector<ContactEvent> events = read_all(scene.space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
    EXPECT_EQ(events[0].body_b, scene.ball);  // the handle it had
    EXPECT_FALSE(scene.space.contains(events[0].body_b));
    EXPECT_EQ(events[0].step, 61u);
}

TEST(ContactEvents, DestroyingASleepingTouchingBody_Ends) {
    Landing scene;
    run(scene.space, 240);
    ASSERT_FALSE(scene.space.internal_is_awake(scene.ball));
    read_all(scene.space);
    scene.space.destroy_body(scene.ground);
    scene.space.flush();
    const std::vector<ContactEvent> events = read_all(scene.space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
    EXPECT_EQ(events[0].body_a, scene.ground);
}

TEST(ContactEvents, FilteredOut_Ends) {
    Landing scene;
    run(scene.space, 60);
    read_all(scene.space);
    scene.space.set_collision_filter(scene.ball, 3, 0);
    scene.space.set_layers_collide(0, 3, false);
    scene.space.update();
    std::vector<ContactEvent> events = read_all(scene.space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
    EXPECT_EQ(events[0].body_b, scene.ball);
    // A body's own filter change ends its touch too.
    Landing other;
    run(other.space, 60);
    read_all(other.space);
    other.space.set_collision_filter(other.ground, 0, 5);
    other.space.set_collision_filter(other.ball, 0, 5);
    other.space.update();
    events = read_all(other.space);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, ContactEventKind::End);
}

TEST(ContactEvents, Hit_HasTheImpactSpeedPointAndNormal) {
    for (const Real drop : {Real(0.5), Real(2), Real(4)}) {
        Space space;
        const BodyHandle ground = add_ground(space);
        BodyDesc d = ball(drop, true, 1.25, -2);
        const BodyHandle b = space.create_body(d);
        run(space, 150);
        std::vector<ContactEvent> events = read_all(space);
        ASSERT_EQ(count(events, ContactEventKind::Hit), 1u) << "drop " << drop;  // no bounce, no hit at rest
        const auto hit = std::find_if(events.begin(), events.end(),
                                      [](const ContactEvent& e) { return e.kind == ContactEventKind::Hit; });
        EXPECT_EQ(hit->body_a, ground);
        EXPECT_EQ(hit->body_b, b);
        const Real expected = std::sqrt(2 * 9.81 * drop);
        // Within half a step's worth of gravity (0.08 m/s) of the free-fall speed.
        EXPECT_NEAR(hit->speed, expected, 0.5 * 9.81 / 60) << "drop " << drop;
        EXPECT_NEAR(hit->normal.y(), 1, 1e-9);  // from the ground (body_a) up to the ball
        EXPECT_NEAR(hit->point.x(), 1.25, 1e-6);
        EXPECT_NEAR(hit->point.z(), -2, 1e-6);
        EXPECT_NEAR(hit->point.y(), 0, 0.05);
    }
}

TEST(ContactEvents, Hit_OnlyAboveTheThreshold) {
    SpaceSettings settings;
    settings.events.hit_speed = 7;  // the 2 m drop lands at 6.3 m/s
    Space space(settings);
    add_ground(space);
    space.create_body(ball(2));
    space.create_body(ball(4, true, 3));  // lands at 8.9 m/s
    run(space, 150);
    const std::vector<ContactEvent> events = read_all(space);
    EXPECT_EQ(count(events, ContactEventKind::Begin), 2u);
    ASSERT_EQ(count(events, ContactEventKind::Hit), 1u);
    for (const ContactEvent& e : events) {
        if (e.kind == ContactEventKind::Hit) {
            EXPECT_GT(e.speed, 7);
        }
    }
}

TEST(ContactEvents, NobodyAsked_NoEventsAndNoWork) {
    Space space;
    add_ground(space);
    for (int i = 0; i < 8; ++i) space.create_body(ball(0.5 + 1.1 * i, false, 0.1 * i));  // a falling column
    run(space, 180);
    EXPECT_GT(space.counters().contacts_updated, 0u);
    EXPECT_EQ(space.counters().contact_event_checks, 0u);
    EXPECT_EQ(read_all(space).size(), 0u);
    EXPECT_EQ(space.dropped_contact_events(), 0u);
}

TEST(ContactEvents, EitherBodyAsking_ReportsThePair) {
    Space space;
    const BodyHandle ground = add_ground(space, true);  // the ground asks, the balls do not
    space.create_body(ball(0.5, false));
    space.create_body(ball(0.5, false, 3));
    run(space, 60);
    const std::vector<ContactEvent> events = read_all(space);
    EXPECT_EQ(count(events, ContactEventKind::Begin), 2u);
    for (const ContactEvent& e : events) EXPECT_EQ(e.body_a, ground);
    EXPECT_GT(space.counters().contact_event_checks, 0u);
}

namespace {

// Balls bouncing on the ground and on each other: many Begins, Ends and Hits.
void add_bouncing_pile(Space& space) {
    add_ground(space);
    for (int i = 0; i < 24; ++i) {
        BodyDesc d = ball(0.2 + 0.9 * (i / 6), true, 0.7 * (i % 6) - 1.75 + 0.13 * (i / 6), 0.3 * (i % 3));
        d.restitution = 0.6;
        space.create_body(d);
    }
}

std::vector<ContactEvent> bouncing_pile_events(JobSystem* jobs, int steps) {
    Space space(SpaceSettings{}, jobs);
    add_bouncing_pile(space);
    std::vector<ContactEvent> events;
    for (int i = 0; i < steps; ++i) {
        space.update();
        space.read_contact_events(events);
    }
    return events;
}

std::unique_ptr<JobSystem> jobs_for(unsigned workers) {
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < workers; ++i)
        options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = false;
    return std::make_unique<WorkStealingJobSystem>(options);
}

}  // namespace

TEST(ContactEvents, SeveralStepsPerUpdate_LoseNothing) {
    const std::vector<ContactEvent> one_by_one = bouncing_pile_events(nullptr, 240);
    ASSERT_GT(count(one_by_one, ContactEventKind::Begin), 24u);
    ASSERT_GT(count(one_by_one, ContactEventKind::End), 0u);
    ASSERT_GT(count(one_by_one, ContactEventKind::Hit), 24u);

    SpaceSettings settings;
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings);
    add_bouncing_pile(space);
    for (int i = 0; i < 60; ++i) {
        space.update(4 * settings.time_step.duration);
        ASSERT_EQ(space.last_update().steps, 4);
    }
    EXPECT_TRUE(same_events(read_all(space), one_by_one));  // read once, after 240 steps in 60 updates
    EXPECT_EQ(space.dropped_contact_events(), 0u);
}

TEST(ContactEvents, ReadingSeldom_LosesNothingAndRepeatsNothing) {
    const std::vector<ContactEvent> every_step = bouncing_pile_events(nullptr, 240);
    Space space;
    add_bouncing_pile(space);
    std::vector<ContactEvent> seldom, batch;
    for (int i = 1; i <= 240; ++i) {
        space.update();
        if (i % 7 == 0 || i == 240) {
            batch.clear();
            const std::size_t n = space.read_contact_events(batch);
            EXPECT_EQ(n, batch.size());
            seldom.insert(seldom.end(), batch.begin(), batch.end());
            EXPECT_EQ(space.read_contact_events(batch), 0u);  // handed over once
        }
    }
    EXPECT_TRUE(same_events(seldom, every_step));
    // Steps never go back, and a pair's Begins and Ends alternate, Begin first.
    std::map<std::pair<std::uint32_t, std::uint32_t>, bool> touching;
    for (std::size_t k = 0; k < seldom.size(); ++k) {
        if (k > 0) {
            EXPECT_LE(seldom[k - 1].step, seldom[k].step);
        }
        if (seldom[k].kind == ContactEventKind::Hit) continue;
        bool& now = touching[{seldom[k].body_a.index, seldom[k].body_b.index}];
        EXPECT_NE(now, seldom[k].kind == ContactEventKind::Begin) << "event " << k;
        now = seldom[k].kind == ContactEventKind::Begin;
    }
}

TEST(ContactEvents, CapReached_DropsAreCountedAndTheQueueIsBounded) {
    const std::vector<ContactEvent> all = bouncing_pile_events(nullptr, 240);
    SpaceSettings settings;
    settings.events.max_queued = 10;
    Space space(settings);
    add_bouncing_pile(space);
    run(space, 240);  // never read while it runs
    const std::vector<ContactEvent> kept = read_all(space);
    EXPECT_EQ(kept.size(), 10u);
    EXPECT_EQ(space.dropped_contact_events(), all.size() - 10);
    // The oldest are kept, in order.
    EXPECT_TRUE(same_events(kept, std::vector<ContactEvent>(all.begin(), all.begin() + 10)));
    EXPECT_EQ(read_all(space).size(), 0u);
}

TEST(ContactEvents, SameSequenceForOneAndTwoWorkers) {
    const std::vector<ContactEvent> reference = bouncing_pile_events(nullptr, 200);
    ASSERT_GT(reference.size(), 50u);
    for (unsigned workers : {1u, 2u}) {
        auto jobs = jobs_for(workers);
        EXPECT_TRUE(same_events(bouncing_pile_events(jobs.get(), 200), reference)) << workers << " workers";
    }
}

// A 12 x 12 grid of balls landing in the same step: about 150 touches begin at once, more
// than one narrowphase range holds, so the workers find them in pieces.
std::vector<ContactEvent> grid_events(JobSystem* jobs) {
    Space space(SpaceSettings{}, jobs);
    add_ground(space);
    for (int i = 0; i < 144; ++i) space.create_body(ball(0.3, true, 1.1 * (i % 12) - 6, 1.1 * (i / 12) - 6));
    std::vector<ContactEvent> events;
    for (int i = 0; i < 40; ++i) {
        space.update();
        space.read_contact_events(events);
    }
    return events;
}

TEST(ContactEvents, ManyAtOnce_SameSequenceForOneToThreeWorkers) {
    const std::vector<ContactEvent> reference = grid_events(nullptr);
    ASSERT_EQ(count(reference, ContactEventKind::Begin), 144u);
    for (unsigned workers : {1u, 2u, 3u}) {
        auto jobs = jobs_for(workers);
        for (int run = 0; run < 3; ++run) {
            EXPECT_TRUE(same_events(grid_events(jobs.get()), reference)) << workers << " workers, run " << run;
        }
    }
}

TEST(ContactEvents, EventsDoNotChangeTheSimulation) {
    auto hash = [](bool events) {
        Space space;
        add_ground(space);
        for (int i = 0; i < 24; ++i) {
            BodyDesc d = ball(0.2 + 0.9 * (i / 6), events, 0.7 * (i % 6) - 1.75 + 0.13 * (i / 6), 0.3 * (i % 3));
            d.restitution = 0.6;
            space.create_body(d);
        }
        run(space, 240);
        return space.state_hash();
    };
    EXPECT_EQ(hash(true), hash(false));
}

TEST(ContactEvents, BadSettings_AreRejectedNamingTheField) {
    SpaceSettings settings;
    settings.events.hit_speed = std::numeric_limits<Real>::quiet_NaN();
    EXPECT_EQ(error_of([&] { Space space(settings); }), "events: hit_speed must be finite and >= 0, got nan");
    settings.events.hit_speed = -1;
    EXPECT_EQ(error_of([&] { Space space(settings); }), "events: hit_speed must be finite and >= 0, got -1");
    settings.events = EventSettings{};
    settings.events.max_queued = 0;
    EXPECT_EQ(error_of([&] { Space space(settings); }), "events: max_queued must be >= 1, got 0");

    Space space;
    EventSettings bad;
    bad.hit_speed = std::numeric_limits<Real>::infinity();
    EXPECT_EQ(error_of([&] { space.set_events(bad); }), "events: hit_speed must be finite and >= 0, got inf");
    EXPECT_EQ(space.settings().events.hit_speed, EventSettings{}.hit_speed);  // unchanged
    EventSettings good;
    good.hit_speed = 3;
    good.max_queued = 7;
    space.set_events(good);
    EXPECT_EQ(space.settings().events.hit_speed, 3);
    EXPECT_EQ(space.settings().events.max_queued, 7u);
}

}  // namespace events_test
