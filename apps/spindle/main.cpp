// The spindle console program: dispatches to the commands (run, bench, scenes,
// layout) and turns their errors into a message and an exit code.
#include <spindle/platform/error.hpp>

#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"

namespace {

constexpr const char* kUsage =
    "usage: spindle <command> [options]     (spindle <command> --help for its options)\n"
    "commands:\n"
    "  run [SCENE] [--layout FILE] [--seconds S] [--render-hz HZ] [--idle MODE] [--trace FILE]\n"
    "      [--record FILE]  play a scene asynchronously (default: the built-in pile, 5 s)\n"
    "  bench SCENE [--threads N] [--steps N] [--substeps N]\n"
    "                      step a scene as fast as possible; prints one line of results\n"
    "  scenes              list the built-in scenes\n"
    "  layout FILE         print how an affinity layout maps onto this machine\n"
    "exit codes: 0 ok, 1 bad file or value, 2 bad command line\n";

}  // namespace

int main(int argc, char** argv) {
    using namespace spindle::app;
    const std::vector<std::string> all(argv + 1, argv + argc);
    const std::string command = all.empty() ? "run" : all[0];
    Args args(command, all.empty() ? std::vector<std::string>{} : std::vector<std::string>(all.begin() + 1, all.end()));
    try {
        if (command == "--help" || command == "-h" || command == "help") {
            std::cout << kUsage;
            return 0;
        }
        if (command == "run") return run_command(args);
        if (command == "bench") return bench_command(args);
        if (command == "scenes") return scenes_command(args);
        if (command == "layout") return layout_command(args);
        std::cerr << "spindle: unknown command '" << command << "'\n" << kUsage;
        return 2;
    } catch (const UsageError& e) {
        std::cerr << "spindle " << command << ": " << e.what() << " (see spindle " << command << " --help)\n";
        return 2;
    } catch (const spindle::Error& e) {
        std::cerr << "spindle " << command << ": " << e.what() << '\n';
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "spindle " << command << ": " << e.what() << '\n';
        return 1;
    }
}
