#include <spindle/platform/clock.hpp>
#include <spindle/platform/error.hpp>
#include <spindle/platform/thread.hpp>
#include <spindle/platform/topology.hpp>

#include <gtest/gtest.h>

#include <thread>

TEST(Thread, PinnedThreadReadsItsBindingBack) {
    const spindle::Topology machine = spindle::Topology::from_system();
    std::thread worker([&] {
        for (const auto& pu : machine.pus()) {
            spindle::pin_current_thread(pu.os_index);
            EXPECT_EQ(spindle::current_binding(), std::vector<unsigned>{pu.os_index});
            // The scheduler moves us off the old CPU once we yield.
            std::this_thread::yield();
            EXPECT_EQ(spindle::current_cpu(), static_cast<int>(pu.os_index));
        }
        spindle::unpin_current_thread();
        EXPECT_EQ(spindle::current_binding().size(), machine.pus().size());
    });
    worker.join();
}

TEST(Thread, PinningANonexistentThreadNamesIt) {
    std::thread worker([] {
        try {
            spindle::pin_current_thread(100000u);
            FAIL() << "expected an error";
        } catch (const spindle::Error& e) {
            EXPECT_NE(std::string(e.what()).find("100000"), std::string::npos) << e.what();
        }
    });
    worker.join();
}

TEST(Thread, NamesAreSetAndTruncated) {
    std::thread worker([] {
        spindle::set_current_thread_name("spindle-worker-number-7");
        EXPECT_EQ(spindle::current_thread_name(), "spindle-worker-");
    });
    worker.join();
}

TEST(Clock, StopwatchLapRestarts) {
    spindle::Stopwatch watch;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    const double first = watch.lap();
    EXPECT_GE(first, 0.002);
    EXPECT_LT(watch.elapsed_seconds(), first + 1.0);
    EXPECT_GT(spindle::now_nanoseconds(), 0);
}
