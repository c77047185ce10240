// The game thread's play for `spindle run --play` (play.hpp).
#include "play.hpp"

#include <spindle/platform/clock.hpp>

#include <chrono>
#include <cmath>

namespace spindle::app {
namespace {

constexpr int kFramesPerShot = 10;     // six shots a second at 60 Hz
constexpr std::size_t kMaxBalls = 60;  // the oldest is retired beyond this
constexpr Real kBallRadius = 0.2;
constexpr Real kShotSpeed = 25;  // m/s

}  // namespace

Player::Player(Space& space, AsyncRunner& runner, const Aabb& bounds)
    : m_space(space), m_runner(runner), m_bounds(bounds) {
    const Vec3 c = bounds.center();
    const Vec3 e = bounds.extents().cwiseMax(Vec3::Constant(1));
    m_trigger = {c - e * 0.25, c + e * 0.25};
}

void Player::frame(double now) {
    collect_shots();
    const Vec3 c = m_bounds.center();
    const Real reach = m_bounds.extents().norm() + 5;
    // A camera circling the scene at a slow walk, aiming at a point that wanders over it.
    const Real turn = 0.2 * now;
    const Vec3 camera = c + Vec3(reach * std::cos(turn), 0.5 * reach, reach * std::sin(turn));
    std::uniform_real_distribution<Real> jitter(-1, 1);
    const Vec3 e = m_bounds.extents();
    const Vec3 aim = c + Vec3(jitter(m_random) * e.x(), jitter(m_random) * e.y(), jitter(m_random) * e.z());

    const std::int64_t t0 = now_nanoseconds();
    const std::optional<QueryHit> pick = m_space.cast_ray(camera, camera + (aim - camera) * 2);
    const bool seen = pick && !m_space.ray_hits_any(camera, pick->point + pick->normal * 1e-3, [&] {
        QueryFilter others;
        others.ignore = pick->body;
        return others;
    }());
    const std::size_t inside = m_space.overlap_box(m_trigger, m_found);
    m_stats.query_seconds += static_cast<double>(now_nanoseconds() - t0) * 1e-9;
    m_stats.queries += pick ? 3 : 2;
    m_stats.picks += pick ? 1 : 0;
    m_stats.in_trigger += inside;

    if (pick && seen && m_stats.frames % kFramesPerShot == 0) shoot(camera, pick->point);
    read_events();
    m_stats.frames += 1;
}

void Player::read_events() {
    m_events.clear();
    const std::int64_t t0 = now_nanoseconds();
    m_space.read_contact_events(m_events);
    m_stats.event_seconds += static_cast<double>(now_nanoseconds() - t0) * 1e-9;
    for (const ContactEvent& e : m_events) {
        const bool begin = e.kind == ContactEventKind::Begin, end = e.kind == ContactEventKind::End;
        if (e.sensor) {
            m_stats.sensor_begins += begin;
            m_stats.sensor_ends += end;
        } else {
            m_stats.begins += begin;
            m_stats.ends += end;
            m_stats.hits += e.kind == ContactEventKind::Hit;
        }
    }
}

void Player::shoot(const Vec3& from, const Vec3& target) {
    BodyDesc ball;
    ball.shape = Shape::sphere(kBallRadius);
    ball.position = from;
    ball.linear_velocity = (target - from).normalized() * kShotSpeed;
    ball.layer = kProjectileLayer;
    ball.fast = true;
    ball.contact_events = true;  // its landings and hits are events
    m_pending.push_back(m_runner.post([ball](Space& space) { return space.create_body(ball); }));
    m_stats.shots += 1;
    if (m_balls.size() >= kMaxBalls) {
        const BodyHandle oldest = m_balls.front();
        m_balls.pop_front();
        m_runner.post([oldest](Space& space) {
            if (space.contains(oldest)) space.destroy_body(oldest);
        });
    }
}

// Created balls join the list once their posted creation has run.
void Player::collect_shots() {
    while (!m_pending.empty()) {
        std::future<BodyHandle>& next = m_pending.front();
        if (next.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
        m_balls.push_back(next.get());  // rethrows a rejected creation
        m_pending.pop_front();
    }
}

}  // namespace spindle::app
