// The spindle console program: `spindle layout FILE`, `spindle run` (until the engine
// exists, run prints the default layout's mapping onto this machine).
#include <spindle/platform/error.hpp>
#include <spindle/platform/layout.hpp>
#include <spindle/platform/topology.hpp>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

namespace {

constexpr const char* kUsage =
    "usage: spindle <command> [options]\n"
    "commands:\n"
    "  run [SCENE] [--layout FILE]   run a scene (default: the embedded default scene)\n"
    "  layout FILE                   print how a layout maps onto this machine\n"
    "  --help                        this text\n";

int print_layout(const spindle::Layout& layout) {
    const spindle::Topology real = spindle::Topology::from_system();
    const spindle::Topology model = layout.model_topology(real);
    const spindle::LayoutMapping mapping = spindle::map_layout(layout, model, real);
    std::cout << "layout " << layout.name << " (" << layout.source << ")\n"
              << "model:   " << model.summary() << "machine: " << real.summary() << mapping.describe();
    return 0;
}

int run(const std::vector<std::string>& args) {
    std::string layout_file;
    for (std::size_t i = 0; i < args.size(); ++i) {
        if (args[i] == "--help") {
            std::cout << "usage: spindle run [SCENE] [--layout FILE]\n";
            return 0;
        }
        if (args[i] == "--layout" && i + 1 < args.size()) {
            layout_file = args[++i];
        } else {
            std::cerr << "spindle run: unknown argument '" << args[i] << "'\n";
            return 2;
        }
    }
    const spindle::Topology real = spindle::Topology::from_system();
    const spindle::Layout layout =
        layout_file.empty() ? spindle::Layout::native(real) : spindle::Layout::load(layout_file, &real);
    return print_layout(layout);
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> args(argv + 1, argv + argc);
    try {
        if (args.empty()) return run({});
        const std::string& command = args[0];
        const std::vector<std::string> rest(args.begin() + 1, args.end());
        if (command == "--help" || command == "-h" || command == "help") {
            std::cout << kUsage;
            return 0;
        }
        if (command == "run") return run(rest);
        if (command == "layout") {
            if (rest.size() != 1 || rest[0] == "--help") {
                std::cerr << "usage: spindle layout FILE\n";
                return rest.size() == 1 ? 0 : 2;
            }
            return print_layout(spindle::Layout::load(rest[0]));
        }
        std::cerr << "spindle: unknown command '" << command << "'\n" << kUsage;
        return 2;
    } catch (const spindle::Error& e) {
        std::cerr << "spindle: " << e.what() << '\n';
        return 1;
    }
}
