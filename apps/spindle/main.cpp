// The spindle console program: the command line (CLI11) of the commands run, bench,
// scenes, layout, view and help, and their errors turned into a message and an exit code.
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <vector>

#include "checks.hpp"
#include "commands.hpp"

namespace {

constexpr int kBadFileOrValue = 1;
constexpr int kBadCommandLine = 2;

// `spindle help [COMMAND]`: the same text as `spindle [COMMAND] --help`.
CLI::App* add_help_command(CLI::App& program, std::string& command) {
    CLI::App* cli = program.add_subcommand("help", "print this help, or a command's");
    cli->add_option("COMMAND", command, "the command whose options to print")
        ->type_name("")
        ->check([&program](const std::string& name) -> std::string {
            for (const CLI::App* sub : program.get_subcommands({})) {
                if (sub->get_name() == name) return {};
            }
            return "unknown command '" + name + "'";
        });
    return cli;
}

// CLI11 calls every argument nobody took "not expected"; the user fixes it sooner when
// told it is an unknown option, an unknown command (at the top level) or one positional
// too many.
std::string describe(const CLI::ParseError& e, const CLI::App& where) {
    const std::vector<std::string> left = where.remaining();
    if (dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr || left.empty()) return e.what();
    const std::string& arg = left.front();
    if (spindle::app::is_option(arg)) return "unknown option '" + arg + "'";
    if (where.get_parent() == nullptr) return "unknown command '" + arg + "'";
    return "unexpected argument '" + arg + "'";
}

}  // namespace

int main(int argc, char** argv) {
    using namespace spindle::app;
    CLI::App program("Spindle's console program: plays, benchmarks and inspects physics scenes.", "spindle");
    program.footer("`spindle COMMAND --help` prints a command's options; without a command, spindle runs the\n"
                   "default scene (`spindle run`).\n"
                   "exit codes: 0 ok, 1 bad file or value, 2 bad command line");
    program.set_help_flag("-h,--help", "print this help and exit");
    program.require_subcommand(0, 1);
    const auto formatter = program.get_formatter();  // shared with the subcommands
    formatter->column_width(20);
    formatter->label("Usage", "usage");
    formatter->label("SUBCOMMAND", "COMMAND");
    formatter->label("Positionals", "Arguments");

    const std::vector<Command> commands = {add_run_command(program), add_bench_command(program),
                                           add_scenes_command(program), add_layout_command(program),
                                           add_view_command(program)};
    std::string help_topic;
    const CLI::App* help = add_help_command(program, help_topic);
    for (CLI::App* sub : program.get_subcommands({})) sub->group("Commands");

    try {
        program.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::cout << program.help();  // the help of the command it was asked of
        return 0;
    } catch (const CLI::ParseError& e) {
        // Leftovers at the top level (an unknown command, an option before the command) are the
        // program's; everything else went wrong in the command given.
        const std::vector<CLI::App*> given = program.get_subcommands();
        const CLI::App& where = given.empty() || program.remaining_size() > 0 ? program : *given.front();
        const std::string name = &where == &program ? "spindle" : "spindle " + where.get_name();
        std::cerr << name << ": " << describe(e, where) << " (see " << name << " --help)\n";
        return kBadCommandLine;
    }

    if (help->parsed()) {
        const CLI::App* topic = help_topic.empty() ? &program : program.get_subcommand(help_topic);
        const std::string name = topic == &program ? "spindle" : "spindle " + help_topic;
        std::cout << formatter->make_help(topic, name, CLI::AppFormatMode::Normal);
        return 0;
    }
    const Command* command = &commands.front();  // no command: run, with its defaults
    for (const Command& c : commands) {
        if (c.cli->parsed()) command = &c;
    }
    try {
        return command->run();
    } catch (const std::exception& e) {
        // spindle::Error from a bad scene, layout or output file; anything else is as much the input's.
        std::cerr << "spindle " << command->cli->get_name() << ": " << e.what() << '\n';
        return kBadFileOrValue;
    }
}
