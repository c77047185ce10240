// `spindle layout FILE`: how an affinity layout maps onto this machine.
#include <spindle/platform/layout.hpp>
#include <spindle/platform/topology.hpp>

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "commands.hpp"

namespace spindle::app {
namespace {

int print_layout(const std::string& file) {
    const Topology real = Topology::from_system();
    const Layout layout = Layout::load(file, &real);
    const Topology model = layout.model_topology(real);
    const LayoutMapping mapping = map_layout(layout, model, real);
    std::cout << "layout " << layout.name << " (" << layout.source << ")\n"
              << "model:   " << model.summary() << "machine: " << real.summary() << mapping.describe();
    return 0;
}

}  // namespace

Command add_layout_command(CLI::App& program) {
    CLI::App* cli = program.add_subcommand("layout", "print how an affinity layout maps onto this machine");
    cli->footer("Prints the modelled machine of an affinity layout (configs/layouts/*.toml), this machine,\n"
                "and which real hardware thread each role (game, physics loop, workers) runs on.");
    auto file = std::make_shared<std::string>();
    cli->add_option("FILE", *file, "the layout file, e.g. configs/layouts/xbox360.toml")->required()->type_name("");
    return {cli, [file] { return print_layout(*file); }};
}

}  // namespace spindle::app
