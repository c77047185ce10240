// The broadphase stage's contact list (stages/broadphase.cpp, contact_list.cpp): the new
// pairs' contacts are decided and filled in parallel ranges, and the lost ones found so,
// yet the list is the one a single thread makes (the pairs' order), whatever job system
// and however its ranges ran; every contact is a pair whose fat boxes overlap and that
// may collide, and the pair index knows every contact's position, also after a filter,
// the layer table, a joint, a motion type, a shape or a body made again took contacts away.
#include <spindle/engine/space.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <set>
#include <vector>

#include "api/space_internals.hpp"
#include "stages/broadphase_state.hpp"
#include "stages/contact_events.hpp"
#include "stages/stages.hpp"
#include "static_bodies.hpp"
#include "test_job_systems.hpp"
#include "world.hpp"

namespace spindle {
namespace {

// What a step left in the contact list, field by field.
struct ContactList {
    std::vector<std::uint64_t> keys;
    std::vector<std::uint32_t> summaries;
    std::vector<Real> friction, restitution;
    std::vector<std::uint8_t> events;
    std::uint32_t reporting = 0;
    std::uint64_t filtered = 0;
    bool operator==(const ContactList&) const = default;
};

// A raw-room array's values, as a plain vector to compare.
template <typename T, typename A>
std::vector<T> values(const std::vector<T, A>& v) {
    return std::vector<T>(v.begin(), v.end());
}

ContactList contact_list(const World& world) {
    ContactList list;
    list.keys = values(world.contact_keys);
    list.summaries = values(world.contact_summaries);
    for (const Contact& c : world.contacts) {
        list.friction.push_back(c.friction);
        list.restitution.push_back(c.restitution);
        list.events.push_back(c.events);
    }
    list.reporting = world.events->reporting;
    list.filtered = world.counters.pairs_filtered;
    return list;
}

// A 24 x 24 x 2 block of touching boxes on a static floor (two thousand new pairs in the
// first step, far more than one job's range), with every kind of pair the broadphase
// turns down or marks: shared groups, layers that do not collide, joints, sensors, a
// kinematic pair; and mixed materials and event flags on the contacts it makes.
struct Block {
    explicit Block(JobSystem& jobs) : space(settings(), &jobs) {
        space.set_layers_collide(1, 2, false);
        test::add_static_box(space, Vec3(30, 1, 30), Vec3(0, -1, 0));
        int n = 0;
        for (int y = 0; y < 2; ++y) {
            for (int i = 0; i < 24; ++i) {
                for (int k = 0; k < 24; ++k, ++n) {
                    BodyDesc d;
                    d.shape = Shape::box(Vec3::Constant(0.5));
                    d.position = Vec3(i - 12, 0.5 + y, k - 12);
                    d.type = n % 97 == 5 || n % 97 == 6 ? MotionType::Kinematic : MotionType::Dynamic;
                    d.group = n % 11 == 0 ? 3 : 0;
                    d.layer = static_cast<std::uint32_t>(n % 3);
                    d.friction = 0.2 + 0.1 * (n % 7);
                    d.restitution = n % 5 == 0 ? 0.3 : 0;
                    d.contact_events = n % 13 == 0;
                    d.sensor = n % 29 == 0;
                    bodies.push_back(space.create_body(d));
                    dynamic.push_back(d.type == MotionType::Dynamic);
                }
            }
        }
        for (std::size_t b = 0; b + 1 < bodies.size(); b += 17) {
            if (!dynamic[b] && !dynamic[b + 1]) continue;
            const Vec3 anchor = space.internal_position(bodies[b]);
            space.create_joint(JointDesc::ball_socket_at(bodies[b], bodies[b + 1], anchor));
        }
    }
    static SpaceSettings settings() {
        SpaceSettings s;
        s.sleep.enabled = false;
        return s;
    }
    Space space;
    std::vector<BodyHandle> bodies;
    std::vector<bool> dynamic;
};

// The pairs the broadphase may make contacts of: fat boxes overlapping, one body dynamic,
// not both sensors, filter and joints allowing.
std::set<std::uint64_t> allowed_overlaps(const World& world) {
    const Bodies& b = world.bodies;
    const BroadphaseState& bp = *world.broadphase;
    std::set<std::uint64_t> pairs;
    for (std::uint32_t i = 0; i < b.capacity(); ++i) {
        for (std::uint32_t j = i + 1; j < b.capacity(); ++j) {
            if (!b.alive[i] || !b.alive[j]) continue;
            if (b.type[i] != MotionType::Dynamic && b.type[j] != MotionType::Dynamic) continue;
            if (b.traits[i].sensor && b.traits[j].sensor) continue;
            if (filter_blocks_pair(world, i, j) || joint_blocks_pair(world.joints, i, j)) continue;
            if (!bp.tree.test_overlap(bp.proxy[i], bp.proxy[j])) continue;
            pairs.insert(std::uint64_t{i} << 32 | j);
        }
    }
    return pairs;
}

// Every contact is a pair the broadphase may make, each such pair has one, and the index
// holds each contact's position.
void expect_contacts_are_the_allowed_overlaps(const World& world) {
    const std::set<std::uint64_t> expected = allowed_overlaps(world);
    const std::set<std::uint64_t> made(world.contact_keys.begin(), world.contact_keys.end());
    ASSERT_EQ(made.size(), world.contact_keys.size()) << "a pair has two contacts";
    EXPECT_EQ(made, expected);
    ContactIndex index = world.contact_index;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const std::uint32_t* position = index.find(world.contact_keys[c]);
        ASSERT_NE(position, nullptr);
        ASSERT_EQ(*position, c);
        ASSERT_EQ(world.contacts[c].body_a, world.contact_keys[c] >> 32);
        ASSERT_EQ(world.contacts[c].body_b, world.contact_keys[c] & 0xffffffffu);
    }
}

// The block's first step, then its top layer teleported away (their contacts lost, from
// positions all through the list) and a step more; the lists after each.
std::vector<ContactList> run_block(JobSystem& jobs) {
    Block block(jobs);
    World& world = SpaceInternals::world(block.space);
    std::vector<ContactList> lists;
    block.space.update();
    expect_contacts_are_the_allowed_overlaps(world);
    lists.push_back(contact_list(world));
    for (std::size_t k = block.bodies.size() / 2; k < block.bodies.size(); k += 2) {
        if (block.dynamic[k]) block.space.set_position(block.bodies[k], Vec3(0, 40 + Real(k), 0));
    }
    block.space.update();
    expect_contacts_are_the_allowed_overlaps(world);
    lists.push_back(contact_list(world));
    return lists;
}

TEST(BroadphaseContacts, FirstStep_ContactsInPairOrderWithTheirMaterialsAndFlags) {
    SingleThreadedJobSystem jobs;
    Block block(jobs);
    block.space.update();
    const World& world = SpaceInternals::world(block.space);
    expect_contacts_are_the_allowed_overlaps(world);
    ASSERT_GT(world.contacts.size(), 2000u);
    EXPECT_TRUE(std::is_sorted(world.contact_keys.begin(), world.contact_keys.end()));
    EXPECT_GT(world.counters.pairs_filtered, 0u);
    std::uint32_t reporting = 0;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const Contact& contact = world.contacts[c];
        const BodyTraits& a = world.bodies.traits[contact.body_a];
        const BodyTraits& b = world.bodies.traits[contact.body_b];
        ASSERT_EQ(contact.friction, std::sqrt(a.friction * b.friction));
        ASSERT_EQ(contact.restitution, std::max(a.restitution, b.restitution));
        ASSERT_EQ(contact.events, contact_event_flags(world, contact.body_a, contact.body_b));
        ASSERT_EQ(world.contact_summaries[c], contact_summary(contact));
        reporting += contact.events != 0 ? 1u : 0u;
    }
    EXPECT_GT(reporting, 0u);
    EXPECT_EQ(world.events->reporting, reporting);
}

// Three threads taking the ranges from the last to the first: the same lists, field for
// field, as one thread in order.
TEST(BroadphaseContacts, SameListsOnThreadsRunningRangesInReverse) {
    SingleThreadedJobSystem single;
    const std::vector<ContactList> reference = run_block(single);
    test::ReverseThreadedJobSystem reverse(3);
    const std::vector<ContactList> lists = run_block(reverse);
    ASSERT_EQ(lists.size(), reference.size());
    for (std::size_t k = 0; k < lists.size(); ++k) {
        EXPECT_TRUE(lists[k] == reference[k]) << "after step " << k + 1;
        EXPECT_EQ(lists[k].keys, reference[k].keys) << "after step " << k + 1;
    }
    EXPECT_LT(reference[1].keys.size(), reference[0].keys.size());  // the teleported layer lost contacts
}

// A body moved most of a box along (out of its fat box) overlaps again many of the boxes
// it had contacts with: the pair search leaves those out where it finds them, so the
// step's new pairs are only pairs without a contact, and the contacts it kept stay.
TEST(BroadphaseContacts, PairsFoundAgainAroundAGrownBox_AreNotNewPairs) {
    SingleThreadedJobSystem jobs;
    Block block(jobs);
    World& world = SpaceInternals::world(block.space);
    block.space.update();
    const std::size_t moved = 24 * 12 + 12;  // inside the bottom layer, dynamic, no sensor
    ASSERT_TRUE(block.dynamic[moved]);
    const std::uint32_t body = block.bodies[moved].index;  // the body's slot
    const std::set<std::uint64_t> before(world.contact_keys.begin(), world.contact_keys.end());
    block.space.set_position(block.bodies[moved], block.space.internal_position(block.bodies[moved]) + Vec3(0.9, 0, 0));
    block.space.update();
    const std::set<std::uint64_t> after(world.contact_keys.begin(), world.contact_keys.end());
    std::size_t kept = 0;
    for (const std::uint64_t key : before) {
        const bool involves = (key >> 32) == body || (key & 0xffffffffu) == body;
        kept += involves && after.count(key) != 0 ? 1u : 0u;
    }
    ASSERT_GT(kept, 0u);  // pairs a search without the contact index would report again
    const PairList& pairs = world.broadphase->pairs;
    bool found_moved = false;
    for (const Pair& p : pairs) {
        EXPECT_EQ(before.count(p.user_a << 32 | p.user_b), 0u) << "pair " << p.user_a << ", " << p.user_b;
        found_moved = found_moved || p.user_a == body || p.user_b == body;
    }
    EXPECT_TRUE(found_moved);  // its new neighbours are found
    expect_contacts_are_the_allowed_overlaps(world);
}

// Bodies of the top layer moved away into a row of their own lose their contacts (made
// in the first step) in the same stage as they make new ones with each other: the lost
// ones are looked for among the contacts made before the stage only, the new ones
// overlapping as they were found, and every lost one is still found.
TEST(BroadphaseContacts, ContactsLostAndMadeInOneStage_TheListIsTheAllowedOverlaps) {
    SingleThreadedJobSystem jobs;
    Block block(jobs);
    World& world = SpaceInternals::world(block.space);
    block.space.update();
    const std::set<std::uint64_t> before(world.contact_keys.begin(), world.contact_keys.end());
    std::set<std::uint32_t> moved;
    for (std::size_t k = block.bodies.size() / 2; k < block.bodies.size() && moved.size() < 40; k += 3) {
        if (!block.dynamic[k]) continue;
        block.space.set_position(block.bodies[k], Vec3(Real(0.95) * Real(moved.size()), 30, 0));
        moved.insert(block.bodies[k].index);
    }
    block.space.update();
    const std::set<std::uint64_t> after(world.contact_keys.begin(), world.contact_keys.end());
    const auto among_moved = [&](std::uint64_t key) {
        return moved.count(static_cast<std::uint32_t>(key >> 32)) != 0 ||
               moved.count(static_cast<std::uint32_t>(key & 0xffffffffu)) != 0;
    };
    std::size_t lost = 0, made = 0;
    for (const std::uint64_t key : before) lost += among_moved(key) && after.count(key) == 0 ? 1u : 0u;
    for (const std::uint64_t key : after) made += among_moved(key) && before.count(key) == 0 ? 1u : 0u;
    EXPECT_GT(lost, 40u);
    EXPECT_GT(made, 10u);
    expect_contacts_are_the_allowed_overlaps(world);
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

// Balls thrown through each other in a space without gravity, never asleep: contacts are
// made and lost in most steps, and the awake list the stages keep up to date (new
// positions appended, removed ones dropped and the last ones renamed to their places) stays the list a
// rebuild from the records gives.
TEST(BroadphaseContacts, AwakeListKeptUpToDate_EqualsARebuild) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.sleep.enabled = false;
    Space space(settings);
    for (int i = 0; i < 200; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        const Real x = Real(i % 20) * 1.2, y = Real(i / 20) * 1.2;
        d.position = {x, y, 0};
        d.linear_velocity = {Real((i * 7) % 5) - 2, Real((i * 3) % 5) - 2, Real((i * 11) % 3) - 1};
        space.create_body(d);
    }
    World& world = SpaceInternals::world(space);
    int kept = 0, made = 0, lost = 0;
    std::size_t before = 0;
    for (int step = 0; step < 120; ++step) {
        space.update();
        const std::size_t now = world.contacts.size();
        made += now > before ? 1 : 0;
        lost += now < before ? 1 : 0;
        before = now;
        if (world.awake_contacts_dirty) continue;
        ++kept;
        std::vector<std::uint32_t> rebuilt;
        for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
            if (!world.contacts[c].sleeping) rebuilt.push_back(c);
        }
        ASSERT_EQ(world.awake_contact_list, rebuilt) << "after step " << step + 1;
    }
    EXPECT_GT(kept, 100);  // the list was up to date after most steps
    EXPECT_GT(made, 5);
    EXPECT_GT(lost, 5);
}

// Contacts made where there were none are the whole awake list, in order, whatever the
// list held: a first step does not rebuild it from tens of thousands of records. Here the
// list is left stale (dirty, with positions in it) when the block's contacts are removed
// and made again.
// The block's first step, then every contact removed: the keys it had.
std::vector<std::uint64_t> make_and_remove_every_contact(Block& block) {
    World& world = SpaceInternals::world(block.space);
    block.space.update();
    const std::vector<std::uint64_t> keys = values(world.contact_keys);
    std::vector<std::uint32_t> all(keys.size());
    std::iota(all.begin(), all.end(), 0u);
    remove_contacts(world, all);
    return keys;
}

TEST(BroadphaseContacts, ContactsMadeFromNone_AreTheAwakeListInOrder) {
    SingleThreadedJobSystem jobs;
    Block block(jobs);
    World& world = SpaceInternals::world(block.space);
    const std::vector<std::uint64_t> keys = make_and_remove_every_contact(block);
    ASSERT_GT(keys.size(), 2000u);
    ASSERT_TRUE(world.contacts.empty());
    std::vector<std::uint32_t> all(keys.size());
    std::iota(all.begin(), all.end(), 0u);
    world.awake_contact_list = {7, 3, 7};
    world.awake_contacts_dirty = true;
    create_contacts(world, keys);
    ASSERT_EQ(world.contacts.size(), keys.size());
    EXPECT_FALSE(world.awake_contacts_dirty);
    EXPECT_EQ(world.awake_contact_list, all);
}

// Fills the room of a raw-room array (grown to hold n, then shrunk to none, its bytes left)
// with `byte`: what a growing resize then leaves unwritten keeps it.
template <typename T>
void fill_room(RawRoomVector<T>& v, std::size_t n, unsigned char byte) {
    v.resize(n);
    std::memset(static_cast<void*>(v.data()), byte, n * sizeof(T));
    v.clear();
}

// The contact array's growth leaves the new records to create_contacts' jobs, which
// construct each in place: records made into room full of 0xff bytes (a removed pile's
// leftovers) are new records, no manifold, no extra, not asleep, with their pair's materials.
// The keys, the summaries and the claimed index slots are raw room too, grown into 0xff and
// 0x5a bytes here: each new key and summary is written, none read before.
TEST(BroadphaseContacts, ContactsMadeIntoDirtyRoom_AreNewRecords) {
    SingleThreadedJobSystem jobs;
    Block block(jobs);
    World& world = SpaceInternals::world(block.space);
    const std::vector<std::uint64_t> keys = make_and_remove_every_contact(block);
    ASSERT_GE(world.contacts.capacity(), keys.size());
    std::memset(static_cast<void*>(world.contacts.data()), 0xff, keys.size() * sizeof(Contact));
    fill_room(world.contact_keys, keys.size(), 0xff);
    fill_room(world.contact_summaries, keys.size(), 0x5a);
    fill_room(world.broadphase->claimed_slots, keys.size(), 0x5a);
    create_contacts(world, keys);
    ASSERT_EQ(values(world.contact_keys), keys);
    ASSERT_EQ(world.contact_summaries.size(), keys.size());
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const Contact& contact = world.contacts[c];
        ASSERT_EQ(world.contact_summaries[c], contact_summary(contact)) << "contact " << c;
        ASSERT_EQ(contact.manifold_count, 0) << "contact " << c;
        ASSERT_TRUE(contact.extra == nullptr);
        ASSERT_FALSE(contact.sleeping);
        ASSERT_FALSE(contact.cached);
        ASSERT_FALSE(contact.touch_reported);
        ASSERT_EQ(contact.friction, std::sqrt(world.bodies.traits[contact.body_a].friction *
                                              world.bodies.traits[contact.body_b].friction));
    }
    block.space.update();  // and a step runs on them
    expect_contacts_are_the_allowed_overlaps(world);
}

// The Bounds jobs' per-body scratch (refit_marked, moved_ids) is raw room too: a first step
// whose scratch grows into room full of 0x5a bytes (each id a valid-looking proxy, each mark
// set) makes the same contacts and the same states as one into zeros, step after step.
TEST(BroadphaseContacts, BoundsScratchGrownIntoDirtyRoom_StepsAsIntoZeros) {
    SingleThreadedJobSystem jobs;
    Block dirty(jobs), clean(jobs);
    for (int step = 0; step < 3; ++step) {
        for (Block* block : {&dirty, &clean}) {
            World& world = SpaceInternals::world(block->space);
            const std::size_t n = world.awake.size() + 16;
            const unsigned char byte = block == &dirty ? 0x5a : 0;
            fill_room(world.broadphase->refit_marked, n, byte);
            fill_room(world.broadphase->moved_ids, n, byte);
            block->space.update();
        }
        const World& a = SpaceInternals::world(dirty.space);
        const World& b = SpaceInternals::world(clean.space);
        ASSERT_EQ(contact_list(a), contact_list(b)) << "step " << step;
        ASSERT_EQ(dirty.space.state_hash(), clean.space.state_hash()) << "step " << step;
        expect_contacts_are_the_allowed_overlaps(a);
    }
}

// A removal fills the removed places with the kept contacts past the new end, so each
// record moves at most once and only as many move as are removed; the index follows the
// moved ones, and the awake list (with sleeping contacts among the moved) stays the
// ascending list a rebuild gives. Removed: the first place, places all through the list,
// and the last two (taken away, not moved).
TEST(BroadphaseContacts, RemovedContacts_TheLastContactsFillTheirPlaces) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.sleep.enabled = false;
    Space space(settings);
    for (int i = 0; i < 100; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.position = {Real(i % 10), Real(i / 10), 0};  // touching neighbours
        space.create_body(d);
    }
    World& world = SpaceInternals::world(space);
    space.update();
    const auto count = static_cast<std::uint32_t>(world.contacts.size());
    ASSERT_GT(count, 100u);
    for (std::uint32_t c = 0; c < count; c += 3) world.contacts[c].sleeping = true;
    world.awake_contacts_dirty = true;
    (void)awake_contacts(world);  // up to date again, so the removal must keep it so

    std::vector<std::uint32_t> removed{0};
    for (std::uint32_t c = 7; c + 2 < count; c += 5) removed.push_back(c);
    removed.push_back(count - 2);
    removed.push_back(count - 1);
    std::vector<std::uint64_t> expected = values(world.contact_keys), removed_keys;
    for (std::uint32_t p : removed) removed_keys.push_back(expected[p]);
    std::set<std::uint64_t> sleeping;
    for (std::uint32_t c = 0; c < count; ++c) {
        if (world.contacts[c].sleeping) sleeping.insert(world.contact_keys[c]);
    }
    for (std::uint32_t p : removed) sleeping.erase(expected[p]);
    // The kept contacts past the new end, in order, into the removed places below it, in order.
    const auto size = static_cast<std::uint32_t>(count - removed.size());
    std::uint32_t from = size;
    for (std::uint32_t p : removed) {
        if (p >= size) break;
        while (std::binary_search(removed.begin(), removed.end(), from)) ++from;
        expected[p] = expected[from++];
    }
    expected.resize(size);
    remove_contacts(world, removed);

    ASSERT_EQ(values(world.contact_keys), expected);
    ASSERT_EQ(world.contacts.size(), expected.size());
    ContactIndex index = world.contact_index;
    std::set<std::uint64_t> still_sleeping;
    std::vector<std::uint32_t> rebuilt;
    for (std::uint32_t c = 0; c < world.contacts.size(); ++c) {
        const std::uint32_t* position = index.find(world.contact_keys[c]);
        ASSERT_NE(position, nullptr);
        ASSERT_EQ(*position, c);
        ASSERT_EQ(world.contacts[c].body_a, world.contact_keys[c] >> 32);  // the record moved with its key
        ASSERT_EQ(world.contacts[c].body_b, world.contact_keys[c] & 0xffffffffu);
        if (world.contacts[c].sleeping) {
            still_sleeping.insert(world.contact_keys[c]);
        } else {
            rebuilt.push_back(c);
        }
    }
    for (std::uint64_t key : removed_keys) EXPECT_EQ(index.find(key), nullptr);
    EXPECT_EQ(still_sleeping, sleeping);
    ASSERT_FALSE(world.awake_contacts_dirty);
    EXPECT_EQ(world.awake_contact_list, rebuilt);
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

// A block of touching spheres big enough that the index claims and erases in jobs (tens of
// thousands of contacts; thousands lost at once when every other sphere of the top layers is
// teleported away). The keys after the first step and after the loss, and the index's
// positions, as one thread makes them.
std::vector<std::vector<std::uint64_t>> run_sphere_block(JobSystem& jobs) {
    SpaceSettings settings;
    settings.gravity = Vec3::Zero();
    settings.sleep.enabled = false;
    Space space(settings, &jobs);
    std::vector<BodyHandle> top;
    for (int y = 0; y < 4; ++y) {
        for (int i = 0; i < 40; ++i) {
            for (int k = 0; k < 40; ++k) {
                BodyDesc d;
                d.shape = Shape::sphere(0.5);
                d.position = {Real(i), Real(y), Real(k)};
                const BodyHandle body = space.create_body(d);
                if (y >= 2 && (i + k) % 2 == 0) top.push_back(body);
            }
        }
    }
    World& world = SpaceInternals::world(space);
    std::vector<std::vector<std::uint64_t>> lists;
    const auto check_index = [&] {
        ContactIndex index = world.contact_index;
        EXPECT_EQ(index.size(), world.contact_keys.size());
        for (std::uint32_t c = 0; c < world.contact_keys.size(); ++c) {
            const std::uint32_t* position = index.find(world.contact_keys[c]);
            ASSERT_NE(position, nullptr);
            ASSERT_EQ(*position, c);
        }
    };
    space.update();
    check_index();
    lists.push_back(values(world.contact_keys));
    for (std::size_t k = 0; k < top.size(); ++k) space.set_position(top[k], Vec3(0, 100 + 3 * Real(k), 0));
    space.update();
    check_index();
    lists.push_back(values(world.contact_keys));
    return lists;
}

TEST(BroadphaseContacts, ManyContactsMadeAndLostOnThreads_AreTheListsOfOneThread) {
    SingleThreadedJobSystem single;
    const std::vector<std::vector<std::uint64_t>> reference = run_sphere_block(single);
    ASSERT_GT(reference[0].size(), 20000u);                      // the index has 65,536 slots or more
    ASSERT_GT(reference[0].size(), reference[1].size() + 2000);  // thousands lost at once
    test::ReverseThreadedJobSystem reverse(3);
    const std::vector<std::vector<std::uint64_t>> lists = run_sphere_block(reverse);
    ASSERT_EQ(lists.size(), reference.size());
    for (std::size_t k = 0; k < lists.size(); ++k) EXPECT_TRUE(lists[k] == reference[k]) << "after step " << k + 1;
}

}  // namespace
}  // namespace spindle

namespace spindle {
namespace {

// The pair search reports a pair only when one of its proxies is new or grew: a pair whose
// fat boxes overlap and that has no contact is found again only if a proxy is made anew
// or touched. So every path that removes a contact while the two fat boxes may still
// overlap (a filter, the layer table, a joint, a motion type, a shape, a body destroyed
// and made again) must make the pair found again at the next step. Each test drifts a
// raft of boxes, takes such a path there and back, and checks after every step that each
// allowed overlap has its contact.

std::set<std::uint64_t> contacts(const World& world) { return {world.contact_keys.begin(), world.contact_keys.end()}; }

// A 6 x 6 raft of touching unit boxes without gravity or sleep, each drifting slowly its
// own way (their fat boxes grow every few steps, mostly where they already were).
struct Raft {
    Raft() : space(settings(), &jobs) {
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 6; ++k) bodies.push_back(space.create_body(desc(i, k)));
        }
    }
    static SpaceSettings settings() {
        SpaceSettings s;
        s.gravity = Vec3::Zero();
        s.sleep.enabled = false;
        return s;
    }
    BodyDesc desc(int i, int k) const {
        BodyDesc d;
        d.shape = Shape::box(Vec3::Constant(0.5));
        d.position = Vec3(i - 2.5, 0.5, k - 2.5);
        const Real angle = 2.4 * (6 * i + k);
        d.linear_velocity = Vec3(std::cos(angle), 0, std::sin(angle)) * 0.4;
        return d;
    }
    World& world() { return SpaceInternals::world(space); }
    BodyHandle at(int i, int k) const { return bodies[static_cast<std::size_t>(6 * i + k)]; }
    std::uint32_t slot(int i, int k) const { return at(i, k).index; }
    // The body at (i, k) and its four neighbours (i, k inside the raft's edge).
    std::vector<BodyHandle> cross(int i, int k) const {
        return {at(i, k), at(i - 1, k), at(i + 1, k), at(i, k - 1), at(i, k + 1)};
    }

    std::set<std::uint64_t> contacts_of(std::uint32_t slot) {
        std::set<std::uint64_t> keys;
        for (const std::uint64_t key : contacts(world())) {
            if ((key >> 32) == slot || (key & 0xffffffffu) == slot) keys.insert(key);
        }
        return keys;
    }
    // Steps `steps` times, checking every allowed overlap has its contact after each.
    void run(int steps) {
        for (int s = 0; s < steps; ++s) {
            space.update();
            ASSERT_EQ(contacts(world()), allowed_overlaps(world())) << "step " << step;
            ++step;
        }
    }
    SingleThreadedJobSystem jobs;
    Space space;
    std::vector<BodyHandle> bodies;
    int step = 0;
};

// A path away (contacts of `slot` removed while the boxes overlap) and back: the pairs
// it gave back must be contacts after the next step. Checks that coming back made
// contacts the body did not have (else the test would prove nothing).
void there_and_back(Raft& raft, std::uint32_t slot, const std::function<void()>& away,
                    const std::function<void()>& back) {
    raft.run(6);
    away();
    raft.run(4);
    const std::set<std::uint64_t> before = raft.contacts_of(slot);
    back();
    raft.run(1);
    std::size_t regained = 0;
    for (const std::uint64_t key : raft.contacts_of(slot)) regained += before.count(key) == 0 ? 1u : 0u;
    EXPECT_GT(regained, 0u);
    raft.run(20);
}

// there_and_back with the body at (2, 2) and its neighbours blocked from one another by
// `block` on each, and the body given back by `allow`.
void block_cross_then_allow(Raft& raft, const std::function<void(BodyHandle)>& block,
                            const std::function<void(BodyHandle)>& allow) {
    const auto block_all = [&] {
        for (const BodyHandle n : raft.cross(2, 2)) block(n);
    };
    there_and_back(raft, raft.slot(2, 2), block_all, [&] { allow(raft.at(2, 2)); });
}

TEST(PairsFoundAgain, FilterBlocksThenAllows_ContactsMadeAgain) {
    Raft raft;
    block_cross_then_allow(
        raft, [&](BodyHandle n) { raft.space.set_collision_filter(n, 0, 5); },  // one group
        [&](BodyHandle n) { raft.space.set_collision_filter(n, 0, 0); });
}

TEST(PairsFoundAgain, LayerTableBlocksThenAllows_ContactsMadeAgain) {
    Raft raft;
    const BodyHandle x = raft.at(3, 2);
    raft.space.set_collision_filter(x, 1, 0);
    there_and_back(
        raft, raft.slot(3, 2), [&] { raft.space.set_layers_collide(0, 1, false); },
        [&] { raft.space.set_layers_collide(0, 1, true); });
}

TEST(PairsFoundAgain, JointMadeThenDestroyed_ContactMadeAgain) {
    Raft raft;
    JointHandle joint;
    there_and_back(
        raft, raft.slot(2, 3),
        [&] {
            const Vec3 middle =
                (raft.space.internal_position(raft.at(2, 3)) + raft.space.internal_position(raft.at(3, 3))) * 0.5;
            joint = raft.space.create_joint(JointDesc::ball_socket_at(raft.at(2, 3), raft.at(3, 3), middle));
        },
        [&] { raft.space.destroy_joint(joint); });
}

TEST(PairsFoundAgain, KinematicPairMadeDynamicAgain_ContactsMadeAgain) {
    Raft raft;
    block_cross_then_allow(
        raft, [&](BodyHandle n) { raft.space.set_motion_type(n, MotionType::Kinematic); },  // no kinematic pairs
        [&](BodyHandle n) { raft.space.set_motion_type(n, MotionType::Dynamic); });
}

// A new shape takes the body's contacts away and makes them again at once: a slightly
// smaller box still overlaps its neighbours, and its box shrank, so only a new search of
// its whole box finds them.
TEST(PairsFoundAgain, ShapeChanged_ContactsMadeAgain) {
    Raft raft;
    const BodyHandle x = raft.at(3, 3);
    raft.run(6);
    raft.space.set_shape(x, Shape::box(Vec3::Constant(0.45)));
    raft.run(1);
    EXPECT_FALSE(raft.contacts_of(raft.slot(3, 3)).empty());
    raft.run(5);
    raft.space.set_shape(x, Shape::box(Vec3::Constant(0.5)));
    raft.run(20);
}

TEST(PairsFoundAgain, BodyDestroyedAndMadeAgainInItsPlace_ContactsMadeAgain) {
    Raft raft;
    BodyDesc again;
    std::uint32_t slot = raft.slot(2, 2);
    there_and_back(
        raft, slot,
        [&] {
            again = raft.desc(2, 2);
            again.position = raft.space.internal_position(raft.at(2, 2));
            raft.space.destroy_body(raft.at(2, 2));
        },
        [&] { ASSERT_EQ(raft.space.create_body(again).index, slot); });  // the slot used again
}

}  // namespace
}  // namespace spindle
