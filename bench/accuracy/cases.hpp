// The hard cases of the accuracy sweep: each builds a small scene, steps it under one
// solver setting and measures its error against an analytic or ideal answer.
#pragma once

#include <span>
#include <string>

#include <spindle/engine/settings.hpp>

namespace spindle::bench {

// One point of the sweep: the knobs a user turns to buy accuracy with time.
struct Setting {
    int substeps = 4;
    int iterations = 1;
    int step_hz = 60;        // step duration is 1 / step_hz seconds
    Real contact_hertz = 0;  // 0: the solver's automatic stiffness, as the sweep runs
    Real dt() const { return 1.0 / step_hz; }
    std::string label() const;  // "4x1 @1/60", or "4x1 @1/60 60 Hz" with a stiffness set
};

// What one run of a case gives back. Only the steps are timed: building the scene and
// measuring between steps are left out, so the time is the solver's price alone.
struct CaseRun {
    double error = 0;
    double step_seconds = 0;       // wall time inside Space::update()
    double simulated_seconds = 0;  // steps x dt
};

struct Case {
    const char* name;
    const char* metric;  // what the error is, for the report
    const char* unit;
    CaseRun (*run)(const Setting&);
};

// Every case, in report order.
std::span<const Case> accuracy_cases();

}  // namespace spindle::bench
