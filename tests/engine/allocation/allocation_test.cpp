// A steady-state step allocates nothing, on the single-threaded job system and on
// work stealing, and a scene's parse allocates in proportion to its bodies: a counting
// global operator new (every thread's) proves it.
#include <spindle/engine/space.hpp>
#include <spindle/platform/topology.hpp>
#include <spindle/scene/scene.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>

#include "static_bodies.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<long> g_bytes{0};
void note_allocation(std::size_t size) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    g_bytes.fetch_add(static_cast<long>(size), std::memory_order_relaxed);
}
}  // namespace

// Every form counts, the no-throw ones too (std::stable_sort's buffer): one left to the
// runtime would be freed by the replaced delete below, another allocator's block.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    note_allocation(size);
    return std::malloc(size ? size : 1);
}
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
    note_allocation(size);
    const auto a = static_cast<std::size_t>(align);
    return std::aligned_alloc(a, (size + a - 1) / a * a);
}
void* operator new(std::size_t size) {
    if (void* p = operator new(size, std::nothrow)) return p;
    throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t align) {
    if (void* p = operator new(size, align, std::nothrow)) return p;
    throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, std::align_val_t align) { return operator new(size, align); }
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t& tag) noexcept {
    return operator new(size, align, tag);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

using namespace spindle;

namespace {

// Two work-stealing workers (on the first two PUs, unpinned: the machine may have one),
// with worker 1's thread running: starting it allocates (its name), and a thread that
// started only during the counted steps would be counted.
std::unique_ptr<JobSystem> two_workers() {
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < 2; ++i) options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = false;
    auto jobs = std::make_unique<WorkStealingJobSystem>(options);
    JobGroup started;
    jobs->submit_pinned(1, started, "started", [] {});
    jobs->wait(started);
    return jobs;
}

// 100 boxes and spheres resting on a plane, awake; `jobs` null: the space's own
// single-threaded job system. Returns the allocations of 120 steps after 120 to settle.
long resting_scene_allocations(JobSystem* jobs) {
    SpaceSettings settings;
    settings.sleep.enabled = false;  // resting but awake: the full pipeline runs every step
    settings.time_step.use_internal_time_stepping = true;
    Space space(settings, jobs);
    test::add_ground_plane(space);
    for (int i = 0; i < 10; ++i) {
        for (int k = 0; k < 10; ++k) {
            BodyDesc d;
            d.shape = (i + k) % 2 ? Shape::sphere(0.5) : Shape::box(Vec3(0.5, 0.5, 0.5));
            d.position = Vec3(1.5 * i, 0.5, 1.5 * k);
            space.create_body(d);
        }
    }
    for (int i = 0; i < 120; ++i) space.update(1.0 / 60.0);  // settle: contacts made, buffers sized
    const long before = g_allocations.load();
    EXPECT_GT(before, 100) << "the counter must see the engine's allocations (setup makes many)";
    for (int i = 0; i < 120; ++i) space.update(1.0 / 60.0);
    const long during = g_allocations.load() - before;
    EXPECT_EQ(space.last_update().contacts, 100u);
    return during;
}

// A hanging chain of ball-socket, hinge (with a motor), fixed and distance joints,
// awake; returns the allocations of 120 steps after 60 to settle.
long jointed_scene_allocations(JobSystem* jobs) {
    SpaceSettings settings;
    settings.sleep.enabled = false;  // hanging still but awake: the joints are solved every step
    Space space(settings, jobs);
    BodyDesc anchor;
    anchor.type = MotionType::Static;
    anchor.shape = Shape::sphere(0.1);
    anchor.position = Vec3(0, 5, 0);
    BodyHandle previous = space.create_body(anchor);
    for (int i = 0; i < 8; ++i) {
        BodyDesc d;
        d.shape = Shape::box(Vec3(0.05, 0.25, 0.05));
        d.position = Vec3(0, 5 - 0.5 * i - 0.25, 0);
        const BodyHandle link = space.create_body(d);
        const Vec3 pivot(0, 5 - 0.5 * i, 0);
        JointDesc j = JointDesc::ball_socket_at(previous, link, pivot);
        if (i % 4 == 1) {
            j = JointDesc::hinge_at(previous, link, pivot, Vec3::UnitZ());
            j.hinge.enable_motor = true;
            j.hinge.max_motor_torque = 1;
            j.hinge.enable_limit = true;
            j.hinge.lower_angle = -0.5;
            j.hinge.upper_angle = 0.5;
        } else if (i % 4 == 2) {
            j = JointDesc::fixed_at(previous, link, pivot);
        } else if (i % 4 == 3) {
            j = JointDesc::distance_between(previous, link, pivot, pivot - Vec3(0, 0.01, 0));
        }
        space.create_joint(j);
        previous = link;
    }
    for (int i = 0; i < 60; ++i) space.update();
    const long before = g_allocations.load();
    for (int i = 0; i < 120; ++i) space.update();
    const long during = g_allocations.load() - before;
    EXPECT_GT(space.counters().joints_solved, 0u);
    return during;
}

// The bytes allocated while parsing a scene of `entries` rows of 20 cubes, as washer's.
long scene_parse_bytes(int entries) {
    std::string text = "[defaults]\nshape = { box = [0.2, 0.2, 0.2] }\n";
    for (int i = 0; i < entries; ++i) {
        text += "[[body]]\nposition = [" + std::to_string(i) + ", 0, 0]\n";
        text += "copies = { count = [1, 1, 20], step = [0, 0, 0.8] }\n";
    }
    const long before = g_bytes.load();
    const SceneDesc scene = parse_scene(text, "rows");
    const long bytes = g_bytes.load() - before;
    EXPECT_EQ(scene.bodies.size(), static_cast<std::size_t>(entries) * 20);
    return bytes;
}

}  // namespace

// Each entry's bodies are added to one list: grown to each entry's exact size, it moved
// every body made so far at every entry, and twice the entries allocated four times the
// bytes.
TEST(Allocation, SceneOfTwiceTheEntriesParsesInAboutTwiceTheBytes) {
    const long one = scene_parse_bytes(200);
    const long two = scene_parse_bytes(400);
    EXPECT_LT(static_cast<double>(two), 2.5 * static_cast<double>(one)) << one << " bytes, then " << two;
}

TEST(Allocation, SteadyStateStepAllocatesNothing) {
    EXPECT_EQ(resting_scene_allocations(nullptr), 0) << "allocations in 120 steady-state steps";
}

TEST(Allocation, SteadyStateStepOnTwoWorkersAllocatesNothing) {
    const std::unique_ptr<JobSystem> jobs = two_workers();
    EXPECT_EQ(resting_scene_allocations(jobs.get()), 0) << "allocations in 120 steady-state steps, 2 workers";
}

TEST(Allocation, SteadyStateJointedStepAllocatesNothing) {
    EXPECT_EQ(jointed_scene_allocations(nullptr), 0) << "allocations in 120 steps of a jointed scene";
}

TEST(Allocation, SteadyStateJointedStepOnTwoWorkersAllocatesNothing) {
    const std::unique_ptr<JobSystem> jobs = two_workers();
    EXPECT_EQ(jointed_scene_allocations(jobs.get()), 0) << "allocations in 120 steps of a jointed scene, 2 workers";
}
