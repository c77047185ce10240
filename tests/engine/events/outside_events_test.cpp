// Contact events under everything a game does to touching bodies at once, as an outside
// tester tried it: destroying and re-creating bodies in one frame, changing their motion
// type, shape, filter and layer table, joining them with joints, teleporting them, while
// some sleep and some are sensors. However it happens, the events stay paired: a pair's
// Begin and End alternate (Begin first), no End comes without a Begin, no Begin names a
// body already destroyed, and once every body is gone every Begin has had its End.
#include <spindle/engine/space.hpp>

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "events_common.hpp"

using namespace spindle;
using namespace spindle::test;

namespace outside_events_test {

namespace {

using PairKey = std::pair<std::uint64_t, std::uint64_t>;

std::uint64_t key_of(BodyHandle h) { return (std::uint64_t{h.generation} << 32) | h.index; }

// Checks the event stream as it is read, update by update.
class PairBook {
public:
    // `destroyed`: handles destroyed so far, with the number of steps taken when each was.
    void read(Space& space, const std::map<std::uint64_t, std::uint64_t>& destroyed) {
        std::vector<ContactEvent> events;
        space.read_contact_events(events);
        for (const ContactEvent& e : events) {
            ASSERT_LT(e.body_a.index, e.body_b.index) << "body_a is the lower slot";
            const PairKey key{key_of(e.body_a), key_of(e.body_b)};
            const std::string what = to_string(e.body_a) + " and " + to_string(e.body_b) + " at step " +
                                     std::to_string(e.step);
            if (e.kind == ContactEventKind::Begin) {
                EXPECT_FALSE(m_open.contains(key)) << "second Begin without an End: " << what;
                for (BodyHandle body : {e.body_a, e.body_b}) {
                    const auto gone = destroyed.find(key_of(body));
                    EXPECT_TRUE(gone == destroyed.end() || e.step <= gone->second)
                        << "Begin names " << to_string(body) << ", destroyed after step " << gone->second << ": "
                        << what;
                }
                m_open[key] = e.sensor;
                ++begins;
            } else if (e.kind == ContactEventKind::End) {
                auto it = m_open.find(key);
                EXPECT_NE(it, m_open.end()) << "End without a Begin: " << what;
                if (it != m_open.end()) {
                    EXPECT_EQ(it->second, e.sensor) << "End's sensor flag differs from its Begin's: " << what;
                    m_open.erase(it);
                }
                ++ends;
            }
            EXPECT_GE(e.step, m_last_step) << "events out of step order: " << what;
            m_last_step = e.step;
        }
    }
    // Pairs begun and not ended that name a body no longer alive.
    std::vector<std::string> open_with_dead(const Space& space) const {
        std::vector<std::string> out;
        for (const auto& [key, sensor] : m_open) {
            const BodyHandle a{static_cast<std::uint32_t>(key.first), static_cast<std::uint32_t>(key.first >> 32)};
            const BodyHandle b{static_cast<std::uint32_t>(key.second), static_cast<std::uint32_t>(key.second >> 32)};
            if (!space.contains(a) || !space.contains(b)) out.push_back(to_string(a) + " and " + to_string(b));
        }
        return out;
    }
    std::size_t open() const { return m_open.size(); }
    int begins = 0, ends = 0;

private:
    std::map<PairKey, bool> m_open;
    std::uint64_t m_last_step = 0;
};

Shape random_shape(std::mt19937& random) {
    switch (random() % 4) {
        case 0: return Shape::sphere(0.4);
        case 1: return Shape::box(Vec3(0.4, 0.3, 0.5));
        case 2: return Shape::capsule(0.3, 0.25);
        default: {
            const CompoundPart parts[] = {{Shape::box(Vec3(0.5, 0.1, 0.3)), Vec3(0, 0.1, 0), Quat::Identity()},
                                          {Shape::sphere(0.25), Vec3(0.4, -0.1, 0), Quat::Identity()}};
            return Shape::compound(parts);
        }
    }
}

BodyDesc random_body(std::mt19937& random) {
    std::uniform_real_distribution<Real> spread(-1.5, 1.5);
    BodyDesc d;
    d.shape = random_shape(random);
    d.position = Vec3(spread(random), 0.4 + 0.6 * (random() % 4), spread(random));
    d.contact_events = random() % 4 != 0;
    d.sensor = random() % 6 == 0;
    d.layer = random() % 3;
    return d;
}

// A crowded little pit of bodies that touch the floor and each other, churned for
// `updates` updates by random changes, reading the events every few updates.
void churn(std::uint32_t seed, int updates) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 random(seed);
    Space space;
    std::vector<BodyHandle> statics;
    BodyDesc floor = static_box(Vec3(3, 0.5, 3), Vec3(0, -0.5, 0));
    floor.contact_events = true;
    statics.push_back(space.create_body(floor));
    BodyDesc sensor_zone = static_box(Vec3(1, 1, 1), Vec3(1, 0.5, 0));
    sensor_zone.sensor = true;
    statics.push_back(space.create_body(sensor_zone));
    std::vector<BodyHandle> bodies;
    for (int i = 0; i < 10; ++i) bodies.push_back(space.create_body(random_body(random)));
    std::vector<JointHandle> joints;
    PairBook book;
    std::map<std::uint64_t, std::uint64_t> destroyed;  // handle: the steps taken when it was destroyed
    auto pick = [&]() -> BodyHandle { return bodies[random() % bodies.size()]; };
    for (int u = 0; u < updates; ++u) {
        const int changes = static_cast<int>(random() % 3);
        for (int c = 0; c < changes; ++c) {
            const BodyHandle b = pick();
            switch (random() % 10) {
                case 0: {  // destroyed and another made at once (it takes the slot)
                    space.destroy_body(b);
                    destroyed[key_of(b)] = space.counters().steps;
                    std::erase(bodies, b);
                    bodies.push_back(space.create_body(random_body(random)));
                    break;
                }
                case 1: {
                    const MotionType types[] = {MotionType::Static, MotionType::Kinematic, MotionType::Dynamic};
                    space.set_motion_type(b, types[random() % 3]);
                    break;
                }
                case 2: space.set_shape(b, random_shape(random)); break;
                case 3: space.set_collision_filter(b, random() % 3, random() % 2); break;
                case 4: space.set_layers_collide(random() % 3, random() % 3, random() % 2 == 0); break;
                case 5: space.set_position(b, Vec3(0, 0.3 + 0.5 * (random() % 3), 0)); break;
                case 6: {
                    const BodyHandle other = pick();
                    if (other == b) break;
                    try {
                        joints.push_back(space.create_joint(JointDesc::ball_socket_at(b, other, Vec3(0, 1, 0))));
                    } catch (const Error&) {
                        // neither dynamic: refused, fine
                    }
                    break;
                }
                case 7:
                    if (!joints.empty()) {
                        const JointHandle j = joints[random() % joints.size()];
                        if (space.contains(j)) space.destroy_joint(j);
                        std::erase(joints, j);
                    }
                    break;
                case 8: space.apply_impulse(b, Vec3(0, 3, 0)); break;
                default: break;  // let it rest (and maybe sleep)
            }
        }
        space.update();
        if (u % 3 == 0) {
            book.read(space, destroyed);
            if (::testing::Test::HasFailure()) return;
        }
    }
    book.read(space, destroyed);
    const std::vector<std::string> dead = book.open_with_dead(space);
    EXPECT_TRUE(dead.empty()) << dead.size() << " pairs name a destroyed body and never ended, first: "
                              << (dead.empty() ? "" : dead.front());
    // Everything goes: every pair still open ends.
    for (BodyHandle b : bodies) space.destroy_body(b);
    for (BodyHandle b : statics) space.destroy_body(b);
    space.update();
    book.read(space, destroyed);
    EXPECT_EQ(book.open(), 0u) << "pairs that began and never ended after every body was destroyed";
    EXPECT_GT(book.begins, 20) << "the churn made too few contacts to test anything";
}

}  // namespace

TEST(OutsideEvents, EveryBeginGetsOneEndWhateverHappensToTheBodies) {
    for (std::uint32_t seed : {1u, 2u, 3u}) churn(seed, 150);
}

// Destroyed and re-created in the same frame in the same slot, touching the same floor:
// the old handle's pair ends and the new handle's begins, never mixed.
TEST(OutsideEvents, DestroyedAndRemadeInOneFrameEndsTheOldPairAndBeginsTheNew) {
    Space space;
    const BodyHandle floor = add_ground(space, true);
    const BodyHandle first = space.create_body(ball(0));
    run(space, 10);
    std::vector<ContactEvent> events = read_all(space);
    ASSERT_EQ(count(events, ContactEventKind::Begin), 1u);
    space.destroy_body(first);
    const BodyHandle second = space.create_body(ball(0));
    ASSERT_EQ(second.index, first.index);
    run(space, 3);
    events = read_all(space);
    ASSERT_EQ(count(events, ContactEventKind::End), 1u);
    ASSERT_EQ(count(events, ContactEventKind::Begin), 1u);
    for (const ContactEvent& e : events) {
        EXPECT_EQ(e.body_a, floor);
        if (e.kind == ContactEventKind::End) {
            EXPECT_EQ(e.body_b, first);
        }
        if (e.kind == ContactEventKind::Begin) {
            EXPECT_EQ(e.body_b, second);
        }
    }
}

// A sensor whose flag-holder is destroyed, made static, or moved away: its overlap ends once.
TEST(OutsideEvents, SensorOverlapEndsOnceWhenTheSensorChangesOrGoes) {
    for (int way = 0; way < 4; ++way) {
        SCOPED_TRACE(way);
        Space space;
        add_ground(space);
        BodyDesc zone = static_box(Vec3(2, 2, 2), Vec3(0, 2, 0));
        zone.sensor = true;
        const BodyHandle sensor = space.create_body(zone);
        const BodyHandle b = space.create_body(ball(0, false));
        run(space, 60);  // the ball rests (and sleeps) inside the zone
        std::vector<ContactEvent> events = read_all(space);
        ASSERT_EQ(count(events, ContactEventKind::Begin), 1u);
        EXPECT_TRUE(events[0].sensor);
        switch (way) {
            case 0: space.destroy_body(sensor); break;
            case 1: space.destroy_body(b); break;
            case 2: space.set_motion_type(b, MotionType::Static); break;  // a sensor detects no static body
            case 3: space.set_position(sensor, Vec3(20, 2, 0)); break;
        }
        run(space, 5);
        events = read_all(space);
        EXPECT_EQ(count(events, ContactEventKind::End), 1u);
        EXPECT_EQ(count(events, ContactEventKind::Begin), 0u);
        for (const ContactEvent& e : events) EXPECT_TRUE(e.sensor);
    }
}

}  // namespace outside_events_test
