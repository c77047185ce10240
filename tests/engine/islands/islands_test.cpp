// Islands and sleeping: resting islands sleep as a whole, cost nothing while asleep,
// and wake together when written to or touched by an awake body.
#include <spindle/engine/space.hpp>
#include <spindle/scheduler/single_threaded.hpp>

#include <gtest/gtest.h>

#include <vector>

#include "static_bodies.hpp"

using namespace spindle;

namespace islands_test {

namespace {

struct Row {
    Space space;
    std::vector<BodyHandle> balls;  // touching each other: one island
};

// Five balls in a touching row on the ground, and one far away.
void build(Row& row) {
    test::add_ground_plane(row.space);
    for (int i = 0; i < 5; ++i) {
        BodyDesc d;
        d.shape = Shape::sphere(0.5);
        d.position = Vec3(0.999 * i, 0.5, 0);
        row.balls.push_back(row.space.create_body(d));
    }
}

bool all_asleep(const Row& row) {
    for (BodyHandle b : row.balls) {
        if (row.space.internal_is_awake(b)) return false;
    }
    return true;
}

void settle(Row& row) {
    for (int i = 0; i < 300 && !all_asleep(row); ++i) row.space.update();
    ASSERT_TRUE(all_asleep(row));
}

}  // namespace

TEST(Islands, RestingIslandSleepsAndCostsNothing) {
    Row row;
    build(row);
    settle(row);
    const WorkCounters before = row.space.counters();
    for (int i = 0; i < 60; ++i) row.space.update();
    const WorkCounters& after = row.space.counters();
    EXPECT_EQ(after.bodies_integrated, before.bodies_integrated);
    EXPECT_EQ(after.contacts_updated, before.contacts_updated);
    EXPECT_EQ(after.contact_points_solved, before.contact_points_solved);
    EXPECT_EQ(after.gravity_applied, before.gravity_applied);
    EXPECT_EQ(row.space.last_update().awake_bodies, 0u);
    for (BodyHandle b : row.balls) EXPECT_NEAR(row.space.position(b).y(), 0.5, 0.01);
}

namespace {

// What steps hand the scheduler: solver plans (run_phases) and parallel ranges with items.
class CountingJobs final : public JobSystem {
public:
    unsigned worker_count() const noexcept override { return 1; }
    void parallel_for(const char* name, std::uint32_t begin, std::uint32_t end, std::uint32_t grain,
                      RangeFn fn) override {
        if (begin < end) ++ranges;
        m_inner.parallel_for(name, begin, end, grain, fn);
    }
    void run_phases(const char* name, std::span<const Phase> phases, PhaseFn fn) override {
        ++phase_runs;
        m_inner.run_phases(name, phases, fn);
    }
    void run_graph(StageGraph& graph) override { m_inner.run_graph(graph); }
    void trace_begin(const char* stage) noexcept override { m_inner.trace_begin(stage); }
    void trace_end() noexcept override { m_inner.trace_end(); }
    int phase_runs = 0, ranges = 0;

private:
    SingleThreadedJobSystem m_inner;
};

}  // namespace

// A world whose bodies all sleep on static ones (large_world's floor of static boxes once
// its spheres rest): a step hands the scheduler no work at all, however many bodies there are.
TEST(Islands, AWorldAtRestHandsTheSchedulerNoWork) {
    CountingJobs jobs;
    Space space(SpaceSettings{}, &jobs);
    for (int i = 0; i < 100; ++i) test::add_static_box(space, Vec3(0.5, 0.5, 0.5), Vec3(i, -0.5, 0));
    BodyDesc ball;
    ball.shape = Shape::sphere(0.25);
    ball.position = Vec3(10, 0.25, 0);
    const BodyHandle resting = space.create_body(ball);
    for (int i = 0; i < 300 && space.internal_is_awake(resting); ++i) space.update();
    ASSERT_FALSE(space.internal_is_awake(resting));
    space.update();  // the flip after the island fell asleep
    jobs.phase_runs = jobs.ranges = 0;
    for (int i = 0; i < 10; ++i) space.update();
    EXPECT_EQ(jobs.phase_runs, 0);
    EXPECT_EQ(jobs.ranges, 0);
}

TEST(Islands, AWriteWakesTheWholeIsland) {
    Row row;
    build(row);
    settle(row);
    row.space.set_linear_velocity(row.balls[4], Vec3(0, 0, 1));
    row.space.update();
    for (BodyHandle b : row.balls) EXPECT_TRUE(row.space.internal_is_awake(b));
}

TEST(Islands, AContactFromAnAwakeBodyWakesTheIsland) {
    Row row;
    build(row);
    settle(row);
    BodyDesc dropped;
    dropped.shape = Shape::sphere(0.5);
    dropped.position = Vec3(2, 3, 0);
    row.space.create_body(dropped);
    bool woke = false;
    for (int i = 0; i < 90 && !woke; ++i) {
        row.space.update();
        woke = row.space.internal_is_awake(row.balls[0]);
    }
    EXPECT_TRUE(woke);
}

TEST(Islands, AnUnrelatedBodyDoesNotWakeTheIsland) {
    Row row;
    build(row);
    settle(row);
    BodyDesc far;
    far.shape = Shape::sphere(0.5);
    far.position = Vec3(50, 5, 0);
    row.space.create_body(far);
    for (int i = 0; i < 30; ++i) row.space.update();
    EXPECT_TRUE(all_asleep(row));
}

TEST(Islands, SleepCanBeDisabled) {
    Row row;
    row.space.set_sleep(SleepSettings{.enabled = false});
    build(row);
    for (int i = 0; i < 300; ++i) row.space.update();
    for (BodyHandle b : row.balls) EXPECT_TRUE(row.space.internal_is_awake(b));
}

TEST(Islands, DestroyingASleepingBodyWakesItsIslandAndForgetsIt) {
    Row row;
    build(row);
    settle(row);
    row.space.destroy_body(row.balls[2]);
    for (std::size_t i : {0u, 1u, 3u, 4u}) EXPECT_TRUE(row.space.internal_is_awake(row.balls[i]));
    // Sleep and wake again: the island must not bring the dead slot back.
    for (int i = 0; i < 300; ++i) row.space.update();
    row.space.set_linear_velocity(row.balls[0], Vec3(0, 0, 1));
    row.space.update();
    EXPECT_FALSE(row.space.contains(row.balls[2]));
    EXPECT_EQ(row.space.body_count(), 5u);  // ground and four balls
    // Without ball 2 the row is two islands: waking ball 0 wakes {0, 1} and nothing else.
    EXPECT_EQ(row.space.last_update().awake_bodies, 2u);
    EXPECT_TRUE(row.space.internal_is_awake(row.balls[1]));
    EXPECT_FALSE(row.space.internal_is_awake(row.balls[3]));
    EXPECT_FALSE(row.space.internal_is_awake(row.balls[4]));
}

}  // namespace islands_test
