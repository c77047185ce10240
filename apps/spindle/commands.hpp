// The spindle commands, one per file: each adds its subcommand (options, checks, help) to
// the program's command line and says how to run it once the line parsed.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace spindle::app {

struct Command {
    CLI::App* cli;  // the subcommand; parsed() when it was given
    // Runs the command with what was parsed (or the defaults) and returns the exit code;
    // a bad file or value is a spindle::Error.
    std::function<int()> run;
};

Command add_run_command(CLI::App& program);     // run.cpp
Command add_bench_command(CLI::App& program);   // bench.cpp
Command add_scenes_command(CLI::App& program);  // scenes.cpp
Command add_layout_command(CLI::App& program);  // layout.cpp
Command add_view_command(CLI::App& program);    // view.cpp

}  // namespace spindle::app
