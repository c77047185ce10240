// `spindle bench --serial`: how much of a step only one worker works in, from the
// scheduler's trace spans, and what that bounds the speed-up on more workers to (Amdahl).
#pragma once

#include <spindle/scheduler/work_stealing.hpp>

#include <span>
#include <string>
#include <vector>

namespace spindle::app {

// Time in which at most one worker had work, under one name: the job running then
// ("<category> <name>", e.g. "Solver WarmStart", "parallel_for Bounds") or, when no worker
// ran a job, the stage whose own code ran ("Islands outside jobs").
struct SerialPart {
    std::string name;
    double seconds = 0;
};

struct SerialProfile {
    unsigned workers = 0;             // the trace's worker count (the largest worker index + 1)
    double step_seconds = 0;          // in stage spans (the union of the physics loop's stages)
    double serial_seconds = 0;        // of step_seconds, with at most one worker working
    double work_seconds = 0;          // worker-seconds of work (idle time counted as one worker's)
    double outside_jobs_seconds = 0;  // of serial_seconds, with no job running: the stages' own code
    std::vector<SerialPart> parts;    // serial_seconds by name, longest first

    // serial_seconds by kind. Inside a run_phases call (a participant's span open, holding
    // its phase spans), one worker alone in a phase before any other began it (the others
    // still coming out of the barrier, or given no block), one alone after the others
    // finished it (its last blocks: the tail), no worker in a phase (all at the barrier);
    // outside it, a lone job, or the stages' own code (outside_jobs_seconds less the
    // barrier time).
    double phase_start_seconds = 0;
    double phase_tail_seconds = 0;
    double barrier_seconds = 0;
    double lone_job_seconds = 0;
    double stage_code_seconds() const { return outside_jobs_seconds - barrier_seconds; }

    // Of the step as it ran: the share of its time with at most one worker working.
    double serial_fraction() const { return step_seconds > 0 ? serial_seconds / step_seconds : 0; }
    // Of the work, as one worker would do it: Amdahl's serial fraction.
    double serial_work_fraction() const { return work_seconds > 0 ? serial_seconds / work_seconds : 0; }
    // Of the work, the stages' own code alone: a floor under serial_work_fraction that the
    // OS taking a worker's core in a job does not raise (it counts jobs as parallel work,
    // whether or not another worker ran beside them).
    double serial_code_fraction() const { return work_seconds > 0 ? outside_jobs_seconds / work_seconds : 0; }
};

// Work is the time in leaf spans: a job span that holds other spans of its worker counts
// only through them (a run_phases participant's chunk holds a span per phase, from its
// first block to its last; between them it waits at a barrier). Stage spans (category
// "stage") mark the step; time in a stage with no job running is the stage's own serial
// code.
SerialProfile serial_profile(std::span<const TraceEvent> events);

// The steps' profiles added up (times summed, parts merged by name, longest first).
SerialProfile sum_profiles(std::span<const SerialProfile> steps);

// The steps whose own serial fraction is at most the median's, summed: on a machine that
// other programs keep busy, a step in which the OS took a worker's core for a while looks
// serial; the quieter half is the step as it runs when it has its cores. On an idle machine
// both halves are alike.
SerialProfile quieter_half(std::span<const SerialProfile> steps);

// Amdahl's bound on the speed-up over one worker with `workers` workers.
double amdahl_speedup(double serial_work_fraction, unsigned workers);

}  // namespace spindle::app
