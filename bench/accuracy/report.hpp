// The sweep's results and what is written from them: the CSV, docs/accuracy.md (tables,
// Pareto fronts, the best trades in words) and the gnuplot script that draws docs/accuracy.png.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "accuracy/cases.hpp"

namespace spindle::bench {

// The default setting with contacts at 60 Hz, their default stiffness until 2ed0b27 (a
// quarter of the substep rate; now an eighth). Run once per case beside the sweep, so the
// report shows what the softer default buys and what it costs.
inline constexpr Setting kQuarterRateContacts{4, 1, 60, 60};

struct Row {
    int case_index = 0;
    Setting setting;
    double ms_per_second = 0;  // wall ms of stepping per simulated second
    double error = 0;
    bool pareto = false;  // no other setting of the case is both cheaper and more accurate
};

struct ReportInfo {
    std::string date;     // UTC
    std::string machine;  // CPU model, logical CPUs, compiler
    int runs = 0;         // most timed runs per point (the fastest is kept)
};

// Marks the Pareto front of every case.
void mark_pareto(std::vector<Row>& rows);

void write_csv(const std::string& path, std::span<const Case> cases, std::span<const Row> rows);
// stiffer: one row per case at kQuarterRateContacts.
void write_markdown(const std::string& path, std::span<const Case> cases, std::span<const Row> rows,
                    std::span<const Row> stiffer, const ReportInfo& info);
// data_path: the points file this writes too; png_path: where gnuplot will draw.
void write_gnuplot(const std::string& script_path, const std::string& data_path, const std::string& png_path,
                   std::span<const Case> cases, std::span<const Row> rows, const ReportInfo& info);

}  // namespace spindle::bench
