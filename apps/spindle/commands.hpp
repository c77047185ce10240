// The spindle commands, one per file; each returns the process exit code and reports a
// bad command line as UsageError, a bad file or value as spindle::Error.
#pragma once

#include "args.hpp"

namespace spindle::app {

int run_command(Args& args);     // run.cpp
int bench_command(Args& args);   // bench.cpp
int scenes_command(Args& args);  // scenes.cpp
int layout_command(Args& args);  // layout.cpp

}  // namespace spindle::app
