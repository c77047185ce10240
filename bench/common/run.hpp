// The main() plumbing both bench programs share: take the program's own flags out of argv,
// hand the rest to Google Benchmark, run whatever was registered.
#pragma once

#include <benchmark/benchmark.h>

#include <vector>

namespace spindle::bench {

// argv without the arguments `take(arg)` consumed (returns true for): argv[0] first,
// null-terminated as main's argv is. Register benchmarks after this, since flags may change them.
template <typename Take>
std::vector<char*> take_own_flags(int argc, char** argv, Take take) {
    std::vector<char*> rest{argv[0]};
    for (int i = 1; i < argc; ++i) {
        if (!take(argv[i])) rest.push_back(argv[i]);
    }
    rest.push_back(nullptr);
    return rest;
}

// Google Benchmark on the remaining arguments. Returns main's exit code (1 for an unknown flag).
inline int run_registered_benchmarks(std::vector<char*>& rest) {
    int count = static_cast<int>(rest.size()) - 1;  // without the terminating null
    benchmark::Initialize(&count, rest.data());
    if (benchmark::ReportUnrecognizedArguments(count, rest.data())) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}

}  // namespace spindle::bench
