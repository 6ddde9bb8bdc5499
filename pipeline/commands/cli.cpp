#include "pipeline/commands/cli.h"

#include <algorithm>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pipeline/commands/command.h"
#include "pipeline/input/scene_fields.h"

namespace apparent {

namespace {

constexpr const char* kDescription =
    "apparent: what objects moving near the speed of light look like, as 3D geometry.\n"
    "Extrudes meshes of moving objects (uniform, spinning or rolling, accelerated, keyframed; the\n"
    "camera at rest or moving) into 4D histories, cuts them with the camera's past lightcone for\n"
    "every frame and exports the apparent shapes (Black et al., Am. J. Phys. 2007).\n"
    "Units: light-seconds and seconds, c = 1.";

// Every command, in the order `apparent --help` lists them (command.h).
using CommandFactory = std::unique_ptr<Command> (*)();
constexpr CommandFactory kCommands[] = {renderCommand, raytraceCommand, figureCommand,
                                        tradeCommand,  measureCommand,  mergeCommand};

}  // namespace

int runCommandLine(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app(kDescription, "apparent");
    app.set_version_flag("--version", "apparent 0.1.0");
    app.require_subcommand(1);
    std::vector<std::unique_ptr<Command>> commands;
    std::vector<CLI::App*> subcommands;
    for (CommandFactory make : kCommands) {
        commands.push_back(make());
        subcommands.push_back(commands.back()->add(&app));
    }

    // An unknown command: CLI11 would say only "A subcommand is required"; name the nearest.
    if (argc > 1 && argv[1][0] != '-') {
        std::vector<std::string> names;
        for (const CLI::App* c : app.get_subcommands({})) names.push_back(c->get_name());
        if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
            const std::string near = nearestField(argv[1], names);
            err << "error: unknown command '" << argv[1] << "'"
                << (near.empty() ? "" : "; did you mean " + near + "?") << " (commands: " << fieldList(names)
                << "; run 'apparent --help')\n";
            return kExitBadInput;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        out << app.help();
        return kExitOk;
    } catch (const CLI::CallForAllHelp&) {
        out << app.help("", CLI::AppFormatMode::All);
        return kExitOk;
    } catch (const CLI::CallForVersion&) {
        out << "apparent 0.1.0\n";
        return kExitOk;
    } catch (const CLI::ParseError& e) {
        // CLI11 throws the subcommand's help as CallForHelp too; everything else is bad usage.
        err << "error: " << e.what() << "\n" << "Run 'apparent --help' or 'apparent render --help'.\n";
        return kExitBadInput;
    }
    // Step: the command given checks its options and runs.
    for (size_t i = 0; i < commands.size(); ++i)
        if (subcommands[i]->parsed()) return commands[i]->run(out, err);
    return kExitBadInput;
}

}  // namespace apparent
