// What state this machine is in, measured rather than guessed from a benchmark's speed: the
// round trip of one cache line between the first two CPUs, and how much two threads on them
// compute beside one (scripts/machine_state.sh builds and runs it). On the project's 2-vCPU VM
// the round trip is 45-90 ns in the fast state and 400-900 ns in the slow one, while two
// threads compute twice what one does in both: the slow state is slow between the cores.
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <thread>

namespace {

using Clock = std::chrono::steady_clock;

void pin(int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

// Mean round trip in ns of a counter passed back and forth between CPUs 0 and 1.
double round_trip_ns(std::int64_t trips) {
    alignas(64) std::atomic<std::int64_t> turn{0};
    std::thread pong([&] {
        pin(1);
        for (std::int64_t i = 0; i < trips; ++i) {
            while (turn.load(std::memory_order_acquire) != 2 * i + 1) {
            }
            turn.store(2 * i + 2, std::memory_order_release);
        }
    });
    pin(0);
    const auto start = Clock::now();
    for (std::int64_t i = 0; i < trips; ++i) {
        turn.store(2 * i + 1, std::memory_order_release);
        while (turn.load(std::memory_order_acquire) != 2 * i + 2) {
        }
    }
    const std::chrono::duration<double, std::nano> took = Clock::now() - start;
    pong.join();
    return took.count() / static_cast<double>(trips);
}

// Millions of steps of a dependent integer loop a second on CPU `cpu`, over `seconds`.
double compute_rate(int cpu, double seconds) {
    pin(cpu);
    volatile std::uint64_t x = 1;
    std::uint64_t steps = 0;
    const auto start = Clock::now();
    std::chrono::duration<double> took{};
    do {
        for (int i = 0; i < 10000; ++i) x = x * 6364136223846793005ull + 1;
        steps += 10000;
        took = Clock::now() - start;
    } while (took.count() < seconds);
    return static_cast<double>(steps) / took.count() / 1e6;
}

}  // namespace

int main() {
    if (std::thread::hardware_concurrency() < 2) {
        std::fprintf(stderr, "machine_state: needs two CPUs\n");
        return 1;
    }
    const double before = round_trip_ns(100000);
    double one = 0, two_a = 0, two_b = 0;
    std::thread([&] { one = compute_rate(0, 0.3); }).join();
    std::thread a([&] { two_a = compute_rate(0, 0.3); });
    std::thread b([&] { two_b = compute_rate(1, 0.3); });
    a.join();
    b.join();
    const double after = round_trip_ns(100000);
    std::printf("round_trip_ns=%.0f,%.0f compute_one=%.0f compute_two=%.0f two_over_one=%.2f\n", before, after, one,
                two_a + two_b, (two_a + two_b) / one);
}
