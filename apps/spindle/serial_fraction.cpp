// The serial fraction of traced steps: a sweep over the workers' leaf job spans inside the
// stage spans.
#include "serial_fraction.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <string_view>

namespace spindle::app {
namespace {

bool is_stage(const TraceEvent& e) { return std::string_view(e.stage ? e.stage : "") == "stage"; }

// A span's end points, in the order the sweep needs them: by time, ends before begins, so
// that back-to-back spans never look like overlapping ones.
enum class Kind : std::uint8_t { Stage, Leaf, Holder };
struct Edge {
    std::int64_t at;
    bool begin;
    std::uint32_t span;  // index into the events
    Kind kind;
};

// Job spans of one worker that hold no other span of that worker (leaves), and those
// that do (holders: a run_phases participant holds its phase spans).
struct WorkerSpans {
    std::vector<std::uint32_t> leaves;
    std::vector<std::uint32_t> holders;
};
WorkerSpans job_spans(std::span<const TraceEvent> events, unsigned worker) {
    std::vector<std::uint32_t> mine;
    for (std::uint32_t i = 0; i < events.size(); ++i) {
        if (!is_stage(events[i]) && events[i].worker == worker) mine.push_back(i);
    }
    // Outer spans before the spans they hold.
    std::sort(mine.begin(), mine.end(), [&](std::uint32_t a, std::uint32_t b) {
        if (events[a].begin_ns != events[b].begin_ns) return events[a].begin_ns < events[b].begin_ns;
        return events[a].end_ns > events[b].end_ns;
    });
    std::vector<bool> holds(mine.size(), false);
    std::vector<std::size_t> open;  // positions in `mine` of the spans that hold the current one
    for (std::size_t k = 0; k < mine.size(); ++k) {
        const TraceEvent& e = events[mine[k]];
        while (!open.empty() && events[mine[open.back()]].end_ns <= e.begin_ns) open.pop_back();
        if (!open.empty()) holds[open.back()] = true;
        open.push_back(k);
    }
    WorkerSpans spans;
    for (std::size_t k = 0; k < mine.size(); ++k) (holds[k] ? spans.holders : spans.leaves).push_back(mine[k]);
    return spans;
}

// Whether an open holder of the span's worker holds it: a run_phases phase span.
bool inside_holder(std::span<const TraceEvent> events, const std::vector<std::uint32_t>& holders,
                   const TraceEvent& span) {
    return std::any_of(holders.begin(), holders.end(), [&](std::uint32_t h) {
        const TraceEvent& holder = events[h];
        return holder.worker == span.worker && holder.begin_ns <= span.begin_ns && span.end_ns <= holder.end_ns;
    });
}

void sort_longest_first(std::vector<SerialPart>& parts) {
    std::sort(parts.begin(), parts.end(), [](const SerialPart& a, const SerialPart& b) {
        return a.seconds != b.seconds ? a.seconds > b.seconds : a.name < b.name;
    });
}

}  // namespace

SerialProfile serial_profile(std::span<const TraceEvent> events) {
    SerialProfile profile;
    for (const TraceEvent& e : events) {
        if (!is_stage(e)) profile.workers = std::max(profile.workers, e.worker + 1);
    }
    std::vector<Edge> edges;
    auto add = [&](std::uint32_t i, Kind kind) {
        edges.insert(edges.end(), {{events[i].begin_ns, true, i, kind}, {events[i].end_ns, false, i, kind}});
    };
    for (std::uint32_t i = 0; i < events.size(); ++i) {
        if (is_stage(events[i])) add(i, Kind::Stage);
    }
    for (unsigned w = 0; w < profile.workers; ++w) {
        const WorkerSpans spans = job_spans(events, w);
        for (std::uint32_t i : spans.leaves) add(i, Kind::Leaf);
        for (std::uint32_t i : spans.holders) add(i, Kind::Holder);
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
        if (a.at != b.at) return a.at < b.at;
        return a.begin < b.begin;
    });

    std::vector<std::uint32_t> stages;   // open stage spans, innermost (latest begun) last
    std::vector<std::uint32_t> jobs;     // open leaf job spans, at most one per worker
    std::vector<std::uint32_t> holders;  // open job spans that hold others (run_phases participants)
    std::vector<std::int64_t> last_leaf_end(profile.workers, std::numeric_limits<std::int64_t>::min());
    std::map<std::string, double> serial_by_name;
    for (std::size_t k = 0; k < edges.size(); ++k) {
        const Edge& edge = edges[k];
        std::vector<std::uint32_t>& open = edge.kind == Kind::Stage ? stages : edge.kind == Kind::Leaf ? jobs : holders;
        if (edge.begin) {
            open.push_back(edge.span);
        } else {
            open.erase(std::find(open.begin(), open.end(), edge.span));
            if (edge.kind == Kind::Leaf) last_leaf_end[events[edge.span].worker] = edge.at;
        }
        if (k + 1 == edges.size() || stages.empty()) continue;
        const double dt = static_cast<double>(edges[k + 1].at - edge.at) * 1e-9;
        if (dt <= 0) continue;
        profile.step_seconds += dt;
        profile.work_seconds += dt * static_cast<double>(std::max<std::size_t>(jobs.size(), 1));
        if (jobs.size() >= 2) continue;
        profile.serial_seconds += dt;
        if (jobs.empty()) profile.outside_jobs_seconds += dt;
        if (jobs.empty()) {
            if (!holders.empty()) profile.barrier_seconds += dt;
        } else if (const TraceEvent& lone = events[jobs.front()]; !inside_holder(events, holders, lone)) {
            profile.lone_job_seconds += dt;
        } else {
            // The tail if another worker worked in this phase and is done with it (phases
            // are apart, barriers between them, so a span that overlapped this one was of
            // the same phase).
            bool others_done = false;
            for (unsigned w = 0; w < profile.workers; ++w)
                others_done = others_done || (w != lone.worker && last_leaf_end[w] > lone.begin_ns);
            (others_done ? profile.phase_tail_seconds : profile.phase_start_seconds) += dt;
        }
        const TraceEvent& who = events[jobs.empty() ? stages.back() : jobs.front()];
        const std::string name = jobs.empty() ? std::string(who.name) + " outside jobs"
                                              : std::string(who.stage ? who.stage : "") + " " + who.name;
        serial_by_name[name] += dt;
    }
    for (const auto& [name, seconds] : serial_by_name) profile.parts.push_back({name, seconds});
    sort_longest_first(profile.parts);
    return profile;
}

SerialProfile sum_profiles(std::span<const SerialProfile> steps) {
    SerialProfile sum;
    std::map<std::string, double> by_name;
    for (const SerialProfile& p : steps) {
        sum.workers = std::max(sum.workers, p.workers);
        sum.step_seconds += p.step_seconds;
        sum.serial_seconds += p.serial_seconds;
        sum.work_seconds += p.work_seconds;
        sum.outside_jobs_seconds += p.outside_jobs_seconds;
        sum.phase_start_seconds += p.phase_start_seconds;
        sum.phase_tail_seconds += p.phase_tail_seconds;
        sum.barrier_seconds += p.barrier_seconds;
        sum.lone_job_seconds += p.lone_job_seconds;
        for (const SerialPart& part : p.parts) by_name[part.name] += part.seconds;
    }
    for (const auto& [name, seconds] : by_name) sum.parts.push_back({name, seconds});
    sort_longest_first(sum.parts);
    return sum;
}

SerialProfile quieter_half(std::span<const SerialProfile> steps) {
    std::vector<SerialProfile> sorted(steps.begin(), steps.end());
    // Stable: steps of equal fractions are taken in step order.
    std::stable_sort(sorted.begin(), sorted.end(), [](const SerialProfile& a, const SerialProfile& b) {
        return a.serial_fraction() < b.serial_fraction();
    });
    sorted.resize((sorted.size() + 1) / 2);
    return sum_profiles(sorted);
}

double amdahl_speedup(double serial_work_fraction, unsigned workers) {
    return 1.0 / (serial_work_fraction + (1.0 - serial_work_fraction) / static_cast<double>(workers));
}

}  // namespace spindle::app
