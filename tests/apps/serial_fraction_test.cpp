// spindle bench --serial's arithmetic (apps/spindle/serial_fraction.cpp) on hand-made spans
// whose serial time is known.
#include "serial_fraction.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace spindle::app {
namespace {

constexpr std::int64_t kUs = 1000;  // spans in microseconds, the trace in nanoseconds

TraceEvent span(const char* category, const char* name, std::int64_t begin_us, std::int64_t end_us, unsigned worker) {
    return TraceEvent{name, category, begin_us * kUs, end_us * kUs, worker, -1};
}

// A 100 us step on two workers:
//   Broadphase [0, 50): job A on worker 0 from 0 and on worker 1 from 10, both to 40; then the
//     stage's own code alone to 50.
//   Solver [50, 100): one run_phases participant per worker ([50, 100) each, holding its
//     blocks); worker 0's Solve blocks [50, 70) and [75, 100), worker 1's [50, 60) and [75, 90).
// One worker or none works in [0, 10), [40, 50), [60, 75) and [90, 100): 45 us.
std::vector<TraceEvent> two_worker_step() {
    return {
        span("stage", "Broadphase", 0, 50, 0),      span("parallel_for", "A", 0, 40, 0),
        span("parallel_for", "A", 10, 40, 1),       span("stage", "Solver", 50, 100, 0),
        span("parallel_for", "Solver", 50, 100, 0), span("Solver", "Solve", 50, 70, 0),
        span("Solver", "Solve", 75, 100, 0),        span("parallel_for", "Solver", 50, 100, 1),
        span("Solver", "Solve", 50, 60, 1),         span("Solver", "Solve", 75, 90, 1),
        span("job", "Late", 100, 120, 1),  // after the step: not part of it
    };
}

TEST(SerialFraction, HandMadeStep_HasTheSerialTimeItWasMadeWith) {
    const SerialProfile p = serial_profile(two_worker_step());
    EXPECT_EQ(p.workers, 2u);
    EXPECT_NEAR(p.step_seconds, 100e-6, 1e-12);
    EXPECT_NEAR(p.serial_seconds, 45e-6, 1e-12);
    EXPECT_NEAR(p.serial_fraction(), 0.45, 1e-9);
    // One worker would take the 45 us plus twice the 55 us both worked.
    EXPECT_NEAR(p.work_seconds, 155e-6, 1e-12);
    EXPECT_NEAR(p.serial_work_fraction(), 45.0 / 155.0, 1e-9);
    // No job ran in [40, 50) and [70, 75).
    EXPECT_NEAR(p.outside_jobs_seconds, 15e-6, 1e-12);
    EXPECT_NEAR(p.serial_code_fraction(), 15.0 / 155.0, 1e-9);

    ASSERT_EQ(p.parts.size(), 4u);
    EXPECT_EQ(p.parts[0].name, "Solver Solve");  // [60, 70) and [90, 100)
    EXPECT_NEAR(p.parts[0].seconds, 20e-6, 1e-12);
    EXPECT_EQ(p.parts[1].name, "Broadphase outside jobs");  // [40, 50)
    EXPECT_NEAR(p.parts[1].seconds, 10e-6, 1e-12);
    EXPECT_EQ(p.parts[2].name, "parallel_for A");  // [0, 10)
    EXPECT_NEAR(p.parts[2].seconds, 10e-6, 1e-12);
    EXPECT_EQ(p.parts[3].name, "Solver outside jobs");  // [70, 75): both participants at the barrier
    EXPECT_NEAR(p.parts[3].seconds, 5e-6, 1e-12);
}

// The hand-made step's serial time by kind: [60, 70) and [90, 100) worker 0 alone after worker
// 1 finished its blocks of the phase (tails), [70, 75) both at the barrier, [0, 10) a lone
// parallel_for chunk, [40, 50) the Broadphase's own code.
TEST(SerialFraction, HandMadeStep_SerialTimeByKind) {
    const SerialProfile p = serial_profile(two_worker_step());
    EXPECT_NEAR(p.phase_tail_seconds, 20e-6, 1e-12);
    EXPECT_EQ(p.phase_start_seconds, 0.0);
    EXPECT_NEAR(p.barrier_seconds, 5e-6, 1e-12);
    EXPECT_NEAR(p.lone_job_seconds, 10e-6, 1e-12);
    EXPECT_NEAR(p.stage_code_seconds(), 10e-6, 1e-12);
}

// Three phases on two workers, each participant's span holding its phase spans:
//   phase 1: worker 0 [0, 10), worker 1 [3, 8): worker 1 late by 3 (start), worker 0 alone [8, 10) (tail);
//   barrier [10, 12);
//   phase 2: worker 1 only [12, 20) (worker 0 got no block): a start, however long;
//   barrier [20, 21);
//   phase 3: worker 0 [21, 30), worker 1 [21, 25): tail [25, 30).
// And after the run_phases call, still in the stage, a job alone on worker 1 [30, 34).
TEST(SerialFraction, PhasesStartAndTail_AreToldApart) {
    const std::vector<TraceEvent> events = {
        span("stage", "Solver", 0, 34, 0),        span("parallel_for", "Solver", 0, 30, 0),
        span("parallel_for", "Solver", 0, 30, 1), span("Solver", "Solve", 0, 10, 0),
        span("Solver", "Solve", 3, 8, 1),         span("Solver", "Relax", 12, 20, 1),
        span("Solver", "Relax", 21, 30, 0),       span("Solver", "Relax", 21, 25, 1),
        span("job", "Last", 30, 34, 1),
    };
    const SerialProfile p = serial_profile(events);
    EXPECT_NEAR(p.serial_seconds, 25e-6, 1e-12);
    EXPECT_NEAR(p.phase_start_seconds, 11e-6, 1e-12);  // [0, 3) and [12, 20)
    EXPECT_NEAR(p.phase_tail_seconds, 7e-6, 1e-12);    // [8, 10) and [25, 30)
    EXPECT_NEAR(p.barrier_seconds, 3e-6, 1e-12);       // [10, 12) and [20, 21)
    EXPECT_NEAR(p.lone_job_seconds, 4e-6, 1e-12);
    EXPECT_EQ(p.stage_code_seconds(), 0.0);
    const SerialProfile twice = sum_profiles(std::vector<SerialProfile>{p, p});
    EXPECT_NEAR(twice.phase_start_seconds, 22e-6, 1e-12);
    EXPECT_NEAR(twice.phase_tail_seconds, 14e-6, 1e-12);
    EXPECT_NEAR(twice.barrier_seconds, 6e-6, 1e-12);
    EXPECT_NEAR(twice.lone_job_seconds, 8e-6, 1e-12);
}

TEST(SerialFraction, SpansInAnyOrder_GiveTheSameProfile) {
    std::vector<TraceEvent> events = two_worker_step();
    std::reverse(events.begin(), events.end());
    const SerialProfile p = serial_profile(events);
    EXPECT_NEAR(p.serial_seconds, 45e-6, 1e-12);
    EXPECT_NEAR(p.work_seconds, 155e-6, 1e-12);
    ASSERT_EQ(p.parts.size(), 4u);
    EXPECT_EQ(p.parts[0].name, "Solver Solve");
}

// Two workers busy together the whole step: nothing serial. One span ending where the next
// begins is not an overlap.
TEST(SerialFraction, FullyParallelStep_HasNoSerialPart) {
    const std::vector<TraceEvent> events = {
        span("stage", "Narrowphase", 0, 10, 0), span("parallel_for", "N", 0, 5, 0), span("parallel_for", "N", 5, 10, 0),
        span("parallel_for", "N", 0, 10, 1),    span("stage", "Solver", 10, 20, 0), span("Solver", "Relax", 10, 20, 0),
        span("Solver", "Relax", 10, 20, 1),
    };
    const SerialProfile p = serial_profile(events);
    EXPECT_EQ(p.serial_seconds, 0.0);
    EXPECT_TRUE(p.parts.empty());
    EXPECT_NEAR(p.work_seconds, 40e-6, 1e-12);
    EXPECT_DOUBLE_EQ(amdahl_speedup(p.serial_work_fraction(), 16), 16.0);
}

// Three steps: the hand-made one, one fully serial (a worker lost its core to another
// program) and one fully parallel. The quieter half is the parallel step and the hand-made one.
TEST(SerialFraction, QuieterHalf_LeavesOutTheStepsThatLookedSerialest) {
    std::vector<SerialProfile> steps;
    steps.push_back(serial_profile(two_worker_step()));
    steps.push_back(serial_profile(
        std::vector<TraceEvent>{span("stage", "Solver", 0, 100, 0), span("Solver", "Solve", 0, 100, 0)}));
    steps.push_back(serial_profile(std::vector<TraceEvent>{
        span("stage", "Solver", 0, 100, 0), span("Solver", "Solve", 0, 100, 0), span("Solver", "Solve", 0, 100, 1)}));

    const SerialProfile all = sum_profiles(steps);
    EXPECT_NEAR(all.step_seconds, 300e-6, 1e-12);
    EXPECT_NEAR(all.serial_seconds, 145e-6, 1e-12);
    ASSERT_FALSE(all.parts.empty());
    EXPECT_EQ(all.parts[0].name, "Solver Solve");
    EXPECT_NEAR(all.parts[0].seconds, 120e-6, 1e-12);

    const SerialProfile quiet = quieter_half(steps);
    EXPECT_NEAR(quiet.step_seconds, 200e-6, 1e-12);
    EXPECT_NEAR(quiet.serial_seconds, 45e-6, 1e-12);
    EXPECT_NEAR(quiet.work_seconds, 355e-6, 1e-12);
    EXPECT_NEAR(all.outside_jobs_seconds, 15e-6, 1e-12);  // the serial step ran its one job
    EXPECT_EQ(quiet.parts.size(), 4u);
    EXPECT_NEAR(quiet.parts[0].seconds, 20e-6, 1e-12);
}

TEST(SerialFraction, Amdahl_BoundsTheSpeedUp) {
    EXPECT_DOUBLE_EQ(amdahl_speedup(1.0, 8), 1.0);
    EXPECT_NEAR(amdahl_speedup(0.05, 4), 1 / (0.05 + 0.95 / 4), 1e-12);
    EXPECT_NEAR(amdahl_speedup(0.05, 16), 9.142857142857, 1e-9);
}

}  // namespace
}  // namespace spindle::app
