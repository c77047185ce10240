// The work-stealing job system: every job once, nesting, DAG order, pinned jobs,
// the waiter helps, exceptions, shutdown, determinism of reductions, trace.
#include <spindle/platform/thread.hpp>
#include <spindle/platform/topology.hpp>
#include <spindle/scheduler/single_threaded.hpp>
#include <spindle/scheduler/work_stealing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <span>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace spindle;

namespace {

#ifdef SPINDLE_TSAN
constexpr std::uint32_t kMillion = 100000;  // TSan is ~10x slower; the logic is the same
#else
constexpr std::uint32_t kMillion = 1000000;
#endif

// n workers on the machine's PUs (round robin), unpinned when there are more workers than PUs.
std::unique_ptr<WorkStealingJobSystem> make(unsigned n) {
    const Topology machine = Topology::from_system();
    WorkStealingJobSystem::Options options;
    for (unsigned i = 0; i < n; ++i) options.worker_pus.push_back(machine.pus()[i % machine.pus().size()].os_index);
    options.pin = n <= machine.pus().size();
    return std::make_unique<WorkStealingJobSystem>(options);
}

double reduce(JobSystem& jobs, const std::vector<double>& values) {
    constexpr std::uint32_t kGrain = 1000;
    const auto n = static_cast<std::uint32_t>(values.size());
    std::vector<double> partial((n + kGrain - 1) / kGrain, 0.0);
    jobs.parallel_for("reduce", 0, n, kGrain, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        double s = 0;
        for (std::uint32_t i = lo; i < hi; ++i) s += values[i];
        partial[lo / kGrain] = s;
    });
    double total = 0;
    for (double p : partial) total += p;  // chunk order: independent of who ran what
    return total;
}

}  // namespace

TEST(WorkStealing, AMillionTinyChunksRunExactlyOnce) {
    auto jobs = make(2);
    std::vector<std::atomic<std::uint8_t>> hits(kMillion);
    jobs->parallel_for("tiny", 0, kMillion, 1, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t i = lo; i < hi; ++i) hits[i].fetch_add(1, std::memory_order_relaxed);
    });
    std::size_t wrong = 0;
    for (auto& h : hits) wrong += h.load() != 1;
    EXPECT_EQ(wrong, 0u);
}

TEST(WorkStealing, AMillionSubmittedJobsRunExactlyOnce) {
    auto jobs = make(2);
    std::vector<std::atomic<std::uint8_t>> hits(kMillion);
    JobGroup group;
    for (std::uint32_t i = 0; i < kMillion; ++i) {
        jobs->submit(group, "job", [&hits, i] { hits[i].fetch_add(1, std::memory_order_relaxed); });
    }
    jobs->wait(group);
    std::size_t wrong = 0;
    for (auto& h : hits) wrong += h.load() != 1;
    EXPECT_EQ(wrong, 0u);
}

TEST(WorkStealing, ChunkBoundariesDependOnlyOnRangeAndGrain) {
    for (unsigned workers : {1u, 2u, 3u}) {
        auto jobs = make(workers);
        std::vector<std::pair<std::uint32_t, std::uint32_t>> chunks(100);
        jobs->parallel_for("chunks", 7, 1000, 10, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
            chunks[(lo - 7) / 10] = {lo, hi};
        });
        for (std::uint32_t c = 0; c < 100; ++c) {
            EXPECT_EQ(chunks[c].first, 7 + 10 * c);
            EXPECT_EQ(chunks[c].second, std::min<std::uint32_t>(1000, 17 + 10 * c));
        }
    }
}

TEST(WorkStealing, NestedParallelForCompletes) {
    auto jobs = make(2);
    std::atomic<std::uint32_t> sum{0};
    jobs->parallel_for("outer", 0, 64, 1, [&](std::uint32_t lo, std::uint32_t, unsigned) {
        jobs->parallel_for("inner", 0, 100, 7, [&](std::uint32_t a, std::uint32_t b, unsigned) {
            sum.fetch_add(b - a, std::memory_order_relaxed);
        });
        (void)lo;
    });
    EXPECT_EQ(sum.load(), 6400u);
}

TEST(WorkStealing, RandomDagsRunInDependencyOrder) {
    auto jobs = make(2);
    std::mt19937 rng(7);
    for (int round = 0; round < 20; ++round) {
        constexpr std::uint32_t kNodes = 60;
        StageGraph graph;
        std::vector<std::atomic<std::int64_t>> finished(kNodes);
        std::atomic<std::int64_t> clock{0};
        std::vector<std::vector<std::uint32_t>> prereqs(kNodes);
        std::atomic<int> violations{0};
        std::vector<std::function<void(unsigned)>> bodies(kNodes);
        for (std::uint32_t i = 0; i < kNodes; ++i) {
            bodies[i] = [&, i](unsigned) {
                for (std::uint32_t p : prereqs[i]) {
                    if (finished[p].load() == 0) violations.fetch_add(1);
                }
                finished[i].store(clock.fetch_add(1) + 1);
            };
        }
        for (std::uint32_t i = 0; i < kNodes; ++i) graph.add("node", bodies[i]);
        for (std::uint32_t i = 1; i < kNodes; ++i) {
            for (int e = 0; e < 3; ++e) {
                const std::uint32_t p = rng() % i;  // edges point forward: a DAG
                prereqs[i].push_back(p);
                graph.depends_on(i, p);
            }
        }
        jobs->run_graph(graph);
        EXPECT_EQ(violations.load(), 0);
        for (auto& f : finished) EXPECT_GT(f.load(), 0);
    }
}

TEST(WorkStealing, PinnedJobRunsOnItsWorkersPu) {
    const Topology machine = Topology::from_system();
    if (machine.pus().size() < 2) GTEST_SKIP() << "needs two hardware threads";
    auto jobs = make(2);
    std::vector<unsigned> binding;
    unsigned worker = 99;
    JobGroup group;
    jobs->submit_pinned(1, group, "pinned", [&](unsigned w) {
        binding = current_binding();
        worker = w;
    });
    jobs->wait(group);
    EXPECT_EQ(worker, 1u);
    EXPECT_EQ(binding, std::vector<unsigned>{machine.pus()[1].os_index});
}

TEST(WorkStealing, TheWaitingThreadRunsJobs) {
    auto jobs = make(2);
    std::atomic<int> by_caller{0};
    jobs->parallel_for("slow", 0, 32, 1, [&](std::uint32_t, std::uint32_t, unsigned worker) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        if (worker == 0) by_caller.fetch_add(1);
    });
    EXPECT_GT(by_caller.load(), 0);
    // A group waited on by a thread whose only other worker is busy still finishes.
    JobGroup group;
    std::atomic<bool> release{false};
    jobs->submit_pinned(1, group, "block", [&] {
        while (!release.load()) std::this_thread::yield();
    });
    JobGroup mine;
    std::atomic<int> ran{0};
    for (int i = 0; i < 10; ++i) jobs->submit(mine, "work", [&] { ran.fetch_add(1); });
    jobs->wait(mine);
    EXPECT_EQ(ran.load(), 10);
    release.store(true);
    jobs->wait(group);
}

TEST(WorkStealing, AnIdleWorkerGetsPartOfABusyWorkersRange) {
    // The lower half is free, the upper half slow: the worker done with its half must be
    // handed part of the other's (ranges are split on demand, not up front). An upper
    // chunk is slow by waiting for the other worker, not for time: the first one a worker
    // runs returns once the other is idle (which it stays until it is handed work), every
    // later one once the other has run an upper chunk. So with the split on demand the
    // next chunk's split hands the idle worker a piece, however late the OS runs either
    // thread; without it the waits end only at the deadline, which turns a hang into a
    // failure and is met by no working scheduler.
    auto jobs = make(2);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    std::array<std::atomic<bool>, 2> ran_upper{};
    std::array<bool, 2> passed_on_idle{};  // each written by its own worker only
    std::vector<unsigned> ran_by(16, 99);
    jobs->parallel_for("skewed", 0, 16, 1, [&](std::uint32_t lo, std::uint32_t, unsigned worker) {
        ran_by[lo] = worker;
        if (lo < 8) return;
        ran_upper[worker].store(true);
        const std::atomic<bool>& other_ran_upper = ran_upper[1 - worker];
        while (!other_ran_upper.load() && std::chrono::steady_clock::now() < deadline) {
            if (!passed_on_idle[worker] && jobs->has_idle_worker()) {
                passed_on_idle[worker] = true;
                break;
            }
            std::this_thread::yield();
        }
    });
    EXPECT_GT(std::count(ran_by.begin() + 8, ran_by.end(), 0u), 0);
    EXPECT_GT(std::count(ran_by.begin() + 8, ran_by.end(), 1u), 0) << "one worker ran the whole slow half";
}

TEST(WorkStealing, AGroupIsDoneWhileItsWorkerRunsAnotherGroupsJob) {
    // Worker 1 runs `quick` (group first), which hands worker 1 `next` (group second), so
    // `next` runs after `quick` on the same worker. A worker counts the finished jobs of a
    // group down together, but must do so before it runs a job of another group: `first`
    // is done while `next` runs. Holding the count back would keep a waiter on `first`
    // waiting for an unrelated job (for ever, if that job waits for the waiter).
    auto jobs = make(2);
    JobGroup first;
    JobGroup second;
    std::atomic<int> first_done_in_next{-1};  // -1: `next` did not run
    jobs->submit_pinned(1, first, "quick", [&] {
        jobs->submit_pinned(1, second, "next", [&] { first_done_in_next.store(first.done() ? 1 : 0); });
    });
    jobs->wait(first);
    jobs->wait(second);
    EXPECT_EQ(first_done_in_next.load(), 1) << "`first` was still pending while its worker ran `next`";
}

TEST(WorkStealing, ExceptionsReachTheWaiter) {
    auto jobs = make(2);
    EXPECT_THROW(jobs->parallel_for("boom", 0, 100, 1,
                                    [&](std::uint32_t lo, std::uint32_t, unsigned) {
                                        if (lo == 57) throw std::runtime_error("chunk 57");
                                    }),
                 std::runtime_error);
    JobGroup group;
    for (int i = 0; i < 10; ++i) {
        jobs->submit(group, "job", [i] {
            if (i == 3) throw std::logic_error("job 3");
        });
    }
    EXPECT_THROW(jobs->wait(group), std::logic_error);
    // The system is still usable afterwards.
    std::atomic<int> n{0};
    jobs->parallel_for("after", 0, 10, 1, [&](std::uint32_t, std::uint32_t, unsigned) { n.fetch_add(1); });
    EXPECT_EQ(n.load(), 10);
}

TEST(WorkStealing, ShutdownWithQueuedWorkRunsEverything) {
    std::atomic<int> ran{0};
    auto groups = std::make_unique<JobGroup[]>(2);
    {
        auto jobs = make(2);
        for (int i = 0; i < 10000; ++i) jobs->submit(groups[0], "queued", [&] { ran.fetch_add(1); });
        jobs->submit_pinned(1, groups[1], "pinned", [&] { ran.fetch_add(1); });
        jobs->submit_pinned(0, groups[1], "pinned0", [&] { ran.fetch_add(1); });
    }  // destroyed without waiting
    EXPECT_EQ(ran.load(), 10002);
}

TEST(WorkStealing, FloatingPointReductionIsBitwiseTheSameForAnyWorkerCount) {
    std::vector<double> values(kMillion / 2);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> dist(-1e6, 1e6);
    for (double& v : values) v = dist(rng) * std::exp(dist(rng) * 1e-5);
    SingleThreadedJobSystem single;
    const double expected = reduce(single, values);
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = make(workers);
        for (int rep = 0; rep < 3; ++rep) {
            const double got = reduce(*jobs, values);
            EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << workers << " workers";
        }
    }
}

TEST(WorkStealing, SingleThreadedRunsGraphsInOrderAndKeepsErrors) {
    SingleThreadedJobSystem single;
    StageGraph graph;
    std::vector<int> order;
    auto a = [&](unsigned) { order.push_back(0); };
    auto b = [&](unsigned) { order.push_back(1); };
    auto c = [&](unsigned) { order.push_back(2); };
    const auto na = graph.add("a", a), nb = graph.add("b", b), nc = graph.add("c", c);
    graph.depends_on(na, nc);  // a after c
    graph.depends_on(nb, na);  // b after a
    single.run_graph(graph);
    EXPECT_EQ(order, (std::vector<int>{2, 0, 1}));
    JobGroup group;
    single.submit(group, "x", [] { throw std::runtime_error("x"); });
    EXPECT_THROW(single.wait(group), std::runtime_error);
}

TEST(WorkStealing, TraceIsChromeJsonNamingJobsStagesWorkersAndPus) {
    auto jobs = make(2);
    jobs->parallel_for("untraced", 0, 10, 1, [](std::uint32_t, std::uint32_t, unsigned) {});
    EXPECT_TRUE(jobs->trace_events().empty());  // off by default
    jobs->enable_trace(true);
    {
        StageScope stage(*jobs, "Narrowphase");
        jobs->parallel_for("pairs", 0, 64, 4, [](std::uint32_t, std::uint32_t, unsigned) {});
    }
    const std::vector<TraceEvent> events = jobs->trace_events();
    ASSERT_EQ(events.size(), 17u);  // 16 chunks + 1 stage
    std::ostringstream json;
    jobs->write_trace(json);
    const std::string text = json.str();
    EXPECT_NE(text.find("\"name\":\"Narrowphase\""), std::string::npos);
    EXPECT_NE(text.find("\"name\":\"pairs\""), std::string::npos);
    EXPECT_NE(text.find("\"pu\":"), std::string::npos);
    const std::string path = ::testing::TempDir() + "spindle_trace.json";
    jobs->write_trace(path);
    const std::string check = "python3 -c \"import json,sys; d=json.load(open('" + path +
                              "')); sys.exit(0 if len(d['traceEvents'])==17 else 1)\"";
    EXPECT_EQ(std::system(check.c_str()), 0);
}

// A worker's chunks of one range are traced end to start: taking the next chunk is its own
// work, so no gap between them may look like time it spent waiting (the serial fraction
// counts such gaps), and a chunk costs one clock read, not two.
TEST(WorkStealing, ConsecutiveChunksOfAWorkerAreTracedEndToStart) {
    auto jobs = make(1);
    jobs->enable_trace(true);
    std::vector<double> sums(16, 0.0);
    jobs->parallel_for("chunks", 0, 64, 4, [&](std::uint32_t lo, std::uint32_t hi, unsigned) {
        for (std::uint32_t i = lo; i < hi; ++i) sums[i / 4] += std::sqrt(static_cast<double>(i));
    });
    const std::vector<TraceEvent> events = jobs->trace_events();
    ASSERT_EQ(events.size(), 16u);  // one worker: every chunk in one range, in order
    for (std::size_t k = 1; k < events.size(); ++k) {
        EXPECT_EQ(events[k].begin_ns, events[k - 1].end_ns) << "chunk " << k;
        EXPECT_LE(events[k].begin_ns, events[k].end_ns);
    }
}

namespace {

// Phases whose items read the previous non-empty phase at scattered places: a phase
// that began before the one it reads had finished would read zeros (and race, for TSan).
struct PhaseChain {
    std::vector<Phase> phases;
    std::vector<std::vector<std::uint64_t>> values;
    std::vector<std::vector<int>> runs;

    PhaseChain() {
        const std::uint32_t counts[] = {1, 0, 7, 1000, 3, 0, 0, 257, 64, 1, 5000, 2, 999};
        for (int round = 0; round < 4; ++round) {
            for (std::uint32_t c : counts) phases.push_back(Phase{"chain", c, 1 + c % 5});
        }
        values.resize(phases.size());
        runs.resize(phases.size());
        for (std::size_t p = 0; p < phases.size(); ++p) {
            values[p].assign(phases[p].count, 0);
            runs[p].assign(phases[p].count, 0);
        }
    }
    const std::vector<std::uint64_t>* source(std::uint32_t p) const {
        while (p-- > 0) {
            if (!values[p].empty()) return &values[p];
        }
        return nullptr;
    }
    void item(std::uint32_t p, std::uint32_t i) {
        std::uint64_t v = p * 1000003ull + i;
        if (const std::vector<std::uint64_t>* in = source(p)) {
            v += (*in)[(i * 7919ull) % in->size()] + 3 * (*in)[in->size() - 1 - i % in->size()];
        }
        values[p][i] = v;
        ++runs[p][i];
    }
    void run(JobSystem& jobs) {
        jobs.run_phases("chain", phases, [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned) {
            for (std::uint32_t i = lo; i < hi; ++i) item(p, i);
        });
    }
};

}  // namespace

TEST(WorkStealing, PhasesRunInOrderEveryItemOnce) {
    PhaseChain expected;
    for (std::uint32_t p = 0; p < expected.phases.size(); ++p) {
        for (std::uint32_t i = 0; i < expected.phases[p].count; ++i) expected.item(p, i);
    }
    SingleThreadedJobSystem serial;
    PhaseChain one;
    one.run(serial);
    EXPECT_EQ(one.values, expected.values);
    for (unsigned workers : {1u, 2u, 3u, 4u}) {
        auto jobs = make(workers);
        for (int repeat = 0; repeat < 5; ++repeat) {
            PhaseChain chain;
            chain.run(*jobs);
            EXPECT_EQ(chain.values, expected.values) << workers << " workers";
            for (const std::vector<int>& r : chain.runs) {
                EXPECT_EQ(std::count(r.begin(), r.end(), 1), static_cast<std::ptrdiff_t>(r.size()));
            }
        }
    }
}

TEST(WorkStealing, AnIdleWorkerTakesPartInPhases) {
    // Two items in two blocks of one phase: each waits (up to a second) for the other to
    // have started, which happens only if two workers run the phase at once.
    auto jobs = make(2);
    bool together = false;
    for (int attempt = 0; attempt < 10 && !together; ++attempt) {
        std::atomic<int> started{0};
        std::atomic<int> met{0};
        const Phase phase{"pair", 2, 1};
        jobs->run_phases("pair", std::span(&phase, 1),
                         [&](std::uint32_t, std::uint32_t lo, std::uint32_t hi, unsigned) {
                             for (std::uint32_t i = lo; i < hi; ++i) {
                                 started.fetch_add(1);
                                 const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
                                 while (started.load() < 2 && std::chrono::steady_clock::now() < until)
                                     std::this_thread::yield();
                                 if (started.load() == 2) met.fetch_add(1);
                             }
                         });
        together = met.load() == 2;
    }
    EXPECT_TRUE(together) << "one worker ran both blocks of the phase in every attempt";
}

TEST(WorkStealing, PhasesFinishWhenAWorkerNeverJoins) {
    // Worker 1 is held by a pinned job for the whole call: worker 0 runs every block
    // itself, then the participant meant for worker 1 walks past the finished phases.
    auto jobs = make(2);
    JobGroup group;
    std::atomic<bool> release{false};
    std::atomic<bool> holding{false};
    jobs->submit_pinned(1, group, "hold", [&] {
        holding.store(true);
        while (!release.load()) std::this_thread::yield();
    });
    while (!holding.load()) std::this_thread::yield();
    PhaseChain chain;
    chain.run(*jobs);
    release.store(true);
    jobs->wait(group);
    PhaseChain expected;
    for (std::uint32_t p = 0; p < expected.phases.size(); ++p) {
        for (std::uint32_t i = 0; i < expected.phases[p].count; ++i) expected.item(p, i);
    }
    EXPECT_EQ(chain.values, expected.values);
}

// The barrier after a phase is each participant's finished blocks added up: no item of a
// phase starts before every item of the phase before it has finished, whichever participant
// finished last (items of uneven cost, so the last finisher and the thieves change from
// phase to phase), and every item runs once.
TEST(WorkStealing, EachPhaseStartsAfterEveryItemOfTheOneBeforeFinished) {
    std::mt19937 rng(19);
    std::vector<Phase> phases;
    for (int p = 0; p < 300; ++p) {
        const auto count = static_cast<std::uint32_t>(std::uniform_int_distribution<int>(2, 40)(rng));
        phases.push_back(Phase{"uneven", count, p % 3 == 0 ? 4u : 1u});
    }
    std::vector<std::uint32_t> cost(phases.size() * 40);
    for (std::uint32_t& c : cost) c = std::uniform_int_distribution<std::uint32_t>(0, 400)(rng);
    for (unsigned workers : {2u, 3u, 4u}) {
        auto jobs = make(workers);
        for (int repeat = 0; repeat < 4; ++repeat) {
            std::vector<std::atomic<std::uint32_t>> finished(phases.size());
            std::vector<std::atomic<std::uint32_t>> runs(phases.size() * 40);
            std::atomic<int> early{0};
            jobs->run_phases("uneven", phases, [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned) {
                if (p > 0 && finished[p - 1].load() != phases[p - 1].count) early.fetch_add(1);
                for (std::uint32_t i = lo; i < hi; ++i) {
                    volatile double x = i;
                    for (std::uint32_t k = 0; k < cost[p * 40 + i]; ++k) x = x * 0.999 + 1;
                    runs[p * 40 + i].fetch_add(1);
                }
                finished[p].fetch_add(hi - lo);
            });
            EXPECT_EQ(early.load(), 0) << workers << " workers: blocks began before the phase before them was over";
            for (std::size_t p = 0; p < phases.size(); ++p) {
                for (std::uint32_t i = 0; i < 40; ++i) {
                    ASSERT_EQ(runs[p * 40 + i].load(), i < phases[p].count ? 1u : 0u) << "phase " << p << " item " << i;
                }
            }
        }
    }
}

// Phases that fit in one block each (count <= grain), one after another, are one round: the
// worker that claims the first runs them all, in order, and the others meet it at one barrier
// after the last; a phase with more blocks, or one after it, is not in the round.
TEST(WorkStealing, ConsecutiveOneBlockPhases_RunBackToBackWithOneBarrier) {
    const Phase phases[] = {
        {"split", 100, 1}, {"tail", 1, 1},   {"tail", 3, 4}, {"empty", 0, 1},
        {"tail", 2, 2},    {"split", 50, 1}, {"tail", 1, 1}, {"split", 9, 1},
    };
    const std::vector<std::uint32_t> round = {1, 2, 4};  // the round of one-block phases
    for (unsigned workers : {2u, 3u}) {
        auto jobs = make(workers);
        for (int repeat = 0; repeat < 20; ++repeat) {
            std::vector<unsigned> ran_on(std::size(phases), ~0u);
            std::vector<int> order(std::size(phases), -1);
            std::atomic<int> next{0};
            std::atomic<int> blocks_split{0};
            const std::uint64_t before = jobs->phase_barriers();
            const std::uint64_t phases_before = jobs->phases_run();
            jobs->run_phases("tails", phases,
                             [&](std::uint32_t p, std::uint32_t lo, std::uint32_t hi, unsigned worker) {
                                 if (std::strcmp(phases[p].name, "split") == 0) {
                                     blocks_split.fetch_add(1);
                                     return;
                                 }
                                 EXPECT_EQ(lo, 0u);
                                 EXPECT_EQ(hi, phases[p].count);
                                 ran_on[p] = worker;
                                 order[p] = next.fetch_add(1);
                             });
            EXPECT_EQ(jobs->phase_barriers() - before, 5u) << workers << " workers: split, round, split, tail, split";
            EXPECT_EQ(jobs->phases_run() - phases_before, 7u);
            for (std::uint32_t p : round) EXPECT_EQ(ran_on[p], ran_on[round[0]]) << "phase " << p;
            EXPECT_LT(order[1], order[2]);
            EXPECT_LT(order[2], order[4]);
            EXPECT_EQ(order[3], -1);  // the empty phase runs nothing
            EXPECT_EQ(order[6], 3);
            EXPECT_GT(blocks_split.load(), 3);
        }
    }
}

namespace {

// The trace of one run_phases call, of phases that do nothing, on two workers.
std::vector<TraceEvent> trace_of_phases(const char* name, std::span<const Phase> phases) {
    auto jobs = make(2);
    jobs->enable_trace(true);
    jobs->run_phases(name, phases, [](std::uint32_t, std::uint32_t, std::uint32_t, unsigned) {});
    return jobs->trace_events();
}

auto named(const char* name) {
    return [name](const TraceEvent& e) { return std::strcmp(e.name, name) == 0; };
}

}  // namespace

// A participant's blocks of a phase are one span (its claims between them are its own
// work; the barrier after them is left out), named after the phase.
TEST(WorkStealing, PhasesAreTracedOnceByEachParticipantThatRanBlocks) {
    const Phase phases[] = {{"alpha", 10, 1}, {"beta", 0, 1}, {"gamma", 3, 1}};
    const std::vector<TraceEvent> events = trace_of_phases("Greek", phases);
    auto count = [&](const char* name) { return std::count_if(events.begin(), events.end(), named(name)); };
    // alpha's 10 items are 8 blocks (two shares of 5, each in blocks of 2, 1, 1, 1), gamma's 3
    // are 3: one span per participant that took any, whoever took which.
    EXPECT_GE(count("alpha"), 1);
    EXPECT_LE(count("alpha"), 2);
    EXPECT_EQ(count("beta"), 0);
    EXPECT_GE(count("gamma"), 1);
    EXPECT_LE(count("gamma"), 2);
    for (const TraceEvent& e : events) {
        if (std::strcmp(e.name, "alpha") == 0 || std::strcmp(e.name, "gamma") == 0) {
            EXPECT_STREQ(e.stage, "Greek");
            EXPECT_LE(e.begin_ns, e.end_ns);
        }
    }
}

// A round of one-block phases runs on one participant, its phases traced end to start.
TEST(WorkStealing, OneBlockRoundIsTracedPhaseAfterPhaseWithoutGaps) {
    const Phase phases[] = {{"one", 1, 1}, {"two", 2, 2}, {"three", 1, 1}};
    const std::vector<TraceEvent> events = trace_of_phases("Round", phases);
    auto find = [&](const char* name) { return std::find_if(events.begin(), events.end(), named(name)); };
    const auto one = find("one"), two = find("two"), three = find("three");
    ASSERT_NE(one, events.end());
    ASSERT_NE(two, events.end());
    ASSERT_NE(three, events.end());
    EXPECT_EQ(one->worker, two->worker);
    EXPECT_EQ(two->worker, three->worker);
    EXPECT_EQ(two->begin_ns, one->end_ns);
    EXPECT_EQ(three->begin_ns, two->end_ns);
}
