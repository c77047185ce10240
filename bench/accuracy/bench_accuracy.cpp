// bench_accuracy: what accuracy costs in time (design.md section 8). Sweeps substeps,
// iterations and step duration over the hard cases of cases.cpp, runs each case once more
// at the default setting with the former default contact stiffness, and writes the CSV,
// the report and the plot script (report.cpp). scripts/accuracy.sh runs it, then gnuplot.
//
//   bench_accuracy [--out DIR] [--docs DIR] [--min-time S] [--quick]
//     --out       CSV, plot data and gnuplot script (default: .)
//     --docs      accuracy.md goes here, and the script draws accuracy.png here (default: docs)
//     --min-time  keep re-running a point until its steps took this long in all (default 0.1 s)
//     --quick     one timed run per point and substeps {1, 4} only: a smoke test
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "accuracy/cases.hpp"
#include "accuracy/report.hpp"

namespace spindle::bench {
namespace {

constexpr int kMaxRuns = 25;  // a point that is slow already has a steady time

struct Options {
    std::string out = ".";
    std::string docs = "docs";
    double min_time = 0.1;
    bool quick = false;
};

std::string utc_now() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", &utc);
    return text;
}

std::string machine() {
    std::string model = "unknown CPU";
    std::ifstream cpuinfo("/proc/cpuinfo");
    for (std::string line; std::getline(cpuinfo, line);) {
        if (line.rfind("model name", 0) == 0) {
            model = line.substr(line.find(':') + 2);
            break;
        }
    }
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " logical CPUs, " +
#if defined(__clang__)
           "clang "
#elif defined(__GNUC__)
           "g++ "
#endif
           + std::string(__VERSION__);
}

// The error of the first run (the cases are deterministic) and the fastest run's time.
Row measure(int case_index, const Case& c, const Setting& setting, const Options& options, int& most_runs) {
    const CaseRun first = c.run(setting);
    double best = first.step_seconds / first.simulated_seconds;
    double spent = first.step_seconds;
    int runs = 1;
    while (!options.quick && spent < options.min_time && runs < kMaxRuns) {
        const CaseRun again = c.run(setting);
        best = std::min(best, again.step_seconds / again.simulated_seconds);
        spent += again.step_seconds;
        ++runs;
    }
    most_runs = std::max(most_runs, runs);
    return {case_index, setting, 1000 * best, first.error, false};
}

int run(const Options& options) {
    const std::vector<int> substeps = options.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 2, 4, 8};
    const int iterations[] = {1, 2};
    const int step_hz[] = {30, 60, 120, 240};
    const auto cases = accuracy_cases();
    std::vector<Row> rows, stiffer;
    ReportInfo info{utc_now(), machine(), 0};
    for (std::size_t ci = 0; ci < cases.size(); ++ci) {
        std::fprintf(stderr, "bench_accuracy: %s\n", cases[ci].name);
        const int index = static_cast<int>(ci);
        for (int s : substeps) {
            for (int i : iterations) {
                for (int hz : step_hz) rows.push_back(measure(index, cases[ci], {s, i, hz}, options, info.runs));
            }
        }
        stiffer.push_back(measure(index, cases[ci], kQuarterRateContacts, options, info.runs));
    }
    mark_pareto(rows);  // the sweep's fronts only: the stiffer rows are a comparison beside it
    std::vector<Row> all = rows;
    all.insert(all.end(), stiffer.begin(), stiffer.end());
    write_csv(options.out + "/accuracy.csv", cases, all);
    write_gnuplot(options.out + "/accuracy.gp", options.out + "/accuracy.dat", options.docs + "/accuracy.png", cases,
                  rows, info);
    write_markdown(options.docs + "/accuracy.md", cases, rows, stiffer, info);
    std::fprintf(stderr, "bench_accuracy: %zu rows -> %s/accuracy.csv, %s/accuracy.md\n", all.size(),
                 options.out.c_str(), options.docs.c_str());
    return 0;
}

}  // namespace
}  // namespace spindle::bench

int main(int argc, char** argv) {
    spindle::bench::Options options;
    for (int i = 1; i < argc; ++i) {
        const bool has_value = i + 1 < argc;
        if (std::strcmp(argv[i], "--out") == 0 && has_value) {
            options.out = argv[++i];
        } else if (std::strcmp(argv[i], "--docs") == 0 && has_value) {
            options.docs = argv[++i];
        } else if (std::strcmp(argv[i], "--min-time") == 0 && has_value) {
            options.min_time = std::atof(argv[++i]);
        } else if (std::strcmp(argv[i], "--quick") == 0) {
            options.quick = true;
        } else {
            std::fprintf(stderr,
                         "bench_accuracy: unknown argument '%s'\n"
                         "usage: bench_accuracy [--out DIR] [--docs DIR] [--min-time S] [--quick]\n",
                         argv[i]);
            return 1;
        }
    }
    try {
        return spindle::bench::run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_accuracy: %s\n", e.what());
        return 1;
    }
}
