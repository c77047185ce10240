// `spindle layout FILE`: how an affinity layout maps onto this machine.
#include <spindle/platform/layout.hpp>
#include <spindle/platform/topology.hpp>

#include <iostream>

#include "commands.hpp"

namespace spindle::app {

int layout_command(Args& args) {
    if (args.help()) {
        std::cout << "usage: spindle layout FILE\n"
                     "Prints the modelled machine of an affinity layout (configs/layouts/*.toml), this machine,\n"
                     "and which real hardware thread each role (game, physics loop, workers) runs on.\n";
        return 0;
    }
    const std::vector<std::string> files = args.positionals(1);
    if (files.empty()) throw UsageError("missing the layout FILE");
    const Topology real = Topology::from_system();
    const Layout layout = Layout::load(files[0], &real);
    const Topology model = layout.model_topology(real);
    const LayoutMapping mapping = map_layout(layout, model, real);
    std::cout << "layout " << layout.name << " (" << layout.source << ")\n"
              << "model:   " << model.summary() << "machine: " << real.summary() << mapping.describe();
    return 0;
}

}  // namespace spindle::app
