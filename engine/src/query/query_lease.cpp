// Taking the published query scene, and making the scenes exist at a space's first query.
//
// The scenes mirror the published buffers (QueryScene::build), and only the physics side
// may read the live state they take shapes and filters from: a thread that holds the
// AccessGate (no update runs) or the update itself. A first query gets them one of three
// ways, and none can wait for the other:
//  - it may take the gate: it builds both scenes and publishes the front one itself,
//    taking the lock as the physics side does (lock_for_publishing), so that a thread
//    holding the lock and waiting for the scenes (below) sees it wait;
//  - it holds the motion-state lock, and the physics side waits for that lock (at a flip,
//    or a creation publishing under the lock): that side has set publisher_waiting()
//    after its last write and clears it only once it has the lock, so until this thread
//    lets go, nothing writes the live state or the buffers and this thread builds both
//    (a shape or filter this update's writes changed then reaches the front scene one
//    step before its reads; the next flip refreshes those bodies);
//  - otherwise it sets World::queries_wanted and waits for the next flip, which builds the
//    scene it publishes from its buffer (stages/buffering.cpp).
// World::query_scenes is written by whoever builds, under the gate or under the lock the
// waiting physics side then takes, so each write happens before the physics side's next
// read of it.
#include "query/query_lease.hpp"

#include <spindle/engine/motion_state_manager.hpp>
#include <spindle/platform/error.hpp>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include "query/query_scene.hpp"
#include "world.hpp"

namespace spindle {

namespace {

// A thread holding the lock waits for the physics side to reach it; past this, something
// else keeps that side from ever asking for the lock (see the error).
constexpr auto kFirstQueryPatience = std::chrono::seconds(10);

void build_missing(World& world, const PublishedBuffer (&buffers)[2]) {
    for (int k = 0; k < 2; ++k) {
        if (!world.query_scenes[k]) world.query_scenes[k] = QueryScene::build(world, buffers[k]);
    }
}

}  // namespace

bool QueryLease::take_locked(World& world) {
    MotionStateManager& manager = world.motion_states;
    if (!manager.m_query_scene) return false;
    m_scene = manager.m_query_scene;
    m_alpha = manager.alpha_locked();
    m_scene->holders.fetch_add(1, std::memory_order_relaxed);  // under the lock
    return true;
}

QueryLease::QueryLease(World& world) {
    MotionStateManager& manager = world.motion_states;
    MotionStateLock& lock = manager.m_lock;
    const bool holding = lock.held_by_this_thread();  // and so for the whole of this call
    const auto since = std::chrono::steady_clock::now();
    for (;;) {
        {
            const MotionStateLock::Hold guard(lock);
            if (take_locked(world)) return;  // every query but the first few
            world.queries_wanted.store(true, std::memory_order_relaxed);
            if (holding && manager.publisher_waiting()) {
                build_missing(world, manager.m_buffers);
                manager.m_query_scene = world.query_scenes[1 - manager.back_index()];
                take_locked(world);
                return;
            }
        }
        {
            const AccessGate::Structure access(world.gate, std::try_to_lock);
            if (access.owns()) {
                build_missing(world, manager.m_buffers);
                std::unique_lock<MotionStateLock> guard;
                if (!holding) {
                    manager.lock_for_publishing();
                    guard = std::unique_lock(lock, std::adopt_lock);
                }
                manager.m_query_scene = world.query_scenes[1 - manager.back_index()];
                take_locked(world);
                return;
            }
        }
        if (holding && std::chrono::steady_clock::now() - since > kFirstQueryPatience) {
            throw Error("scene query: the space's first query, made while holding the motion-state lock, waited " +
                        std::to_string(kFirstQueryPatience.count()) +
                        " s for the physics thread to reach a flip; it is waiting for something this thread holds "
                        "(make the first query without holding the lock)");
        }
        std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
}

QueryLease::~QueryLease() {
    // Release: this query's reads happen before the physics thread's next writes.
    m_scene->holders.fetch_sub(1, std::memory_order_release);
}

}  // namespace spindle
