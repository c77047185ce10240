// `spindle run --play`: what a game does on its own thread beside rendering, while the
// physics loop runs (issue 17). Each frame it picks a target with a ray from a camera
// circling the scene, checks the line of sight to it, now and then shoots a ball at it
// (created on the physics thread through AsyncRunner::post, its velocity a buffered
// write), retires the oldest balls, and counts what the queries found and the time they
// took on the game thread; and it reads the contact and sensor events the physics thread
// published since the last frame.
#pragma once

#include <spindle/engine/async_runner.hpp>
#include <spindle/engine/space.hpp>

#include <cstdint>
#include <deque>
#include <future>
#include <random>
#include <vector>

namespace spindle::app {

// Balls the player shoots: their own layer, so a scene can say what they pass through
// ([settings] ignore_layers).
inline constexpr std::uint32_t kProjectileLayer = 1;

struct PlayStats {
    std::uint64_t frames = 0;
    std::uint64_t queries = 0;  // ray casts and overlaps made
    std::uint64_t picks = 0;    // frames whose pick ray hit a body
    std::uint64_t shots = 0;
    std::uint64_t in_trigger = 0;                  // sum over frames of the bodies the overlap found in the trigger box
    double query_seconds = 0;                      // game-thread time inside the queries
    std::uint64_t begins = 0, ends = 0, hits = 0;  // contact events read (sensor ones apart)
    std::uint64_t sensor_begins = 0, sensor_ends = 0;
    double event_seconds = 0;  // game-thread time reading them
};

class Player {
public:
    // bounds: where the scene's bodies are (the camera circles it, the trigger box is its
    // middle). The space and runner must outlive the player.
    Player(Space& space, AsyncRunner& runner, const Aabb& bounds);

    // One frame's play at wall time `now`. Rethrows what a posted creation threw.
    void frame(double now);
    const PlayStats& stats() const noexcept { return m_stats; }

private:
    void shoot(const Vec3& from, const Vec3& target);
    void collect_shots();
    void read_events();

    Space& m_space;
    AsyncRunner& m_runner;
    Aabb m_bounds;
    Aabb m_trigger;
    std::mt19937 m_random{17};
    std::deque<BodyHandle> m_balls;  // oldest first
    std::deque<std::future<BodyHandle>> m_pending;
    std::vector<BodyHandle> m_found;
    std::vector<ContactEvent> m_events;
    PlayStats m_stats;
};

}  // namespace spindle::app
