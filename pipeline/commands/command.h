// One command of `apparent`: its subcommand and options on the command line, then, when it is the
// one given, its options turned into settings (one line per problem, exit code 2) and run. Every
// command is one row of cli.cpp's table, in the order `apparent --help` lists them; its class lives
// in the command's own file, beside the function that does the work.
//
// Adding a command: a file in pipeline/commands/ with a Command whose add() declares the options
// (addStageLimits for a command that loads a scene, parseModelList and parseFrames for the shared
// ones) and whose run() checks them and calls the work inside guarded(); its factory declared
// below; one row in cli.cpp; the file in CMakeLists.txt; an end-to-end test in tests/.
#pragma once

#include <exception>
#include <memory>
#include <new>
#include <ostream>
#include <string>
#include <vector>

#include "pipeline/stage/stage.h"

namespace CLI {
class App;
}

namespace apparent {

class Command {
public:
    virtual ~Command() = default;
    // Adds the subcommand with its options to `app`; the options write into this object.
    virtual CLI::App* add(CLI::App* app) = 0;
    // After parsing, when this command was given: checks its options and runs it (the exit code).
    virtual int run(std::ostream& out, std::ostream& err) = 0;
};

std::unique_ptr<Command> renderCommand();    // render.cpp
std::unique_ptr<Command> raytraceCommand();  // raytrace_command.cpp
std::unique_ptr<Command> figureCommand();    // figure_command.cpp
std::unique_ptr<Command> tradeCommand();     // trade.cpp
std::unique_ptr<Command> measureCommand();   // measure.cpp
std::unique_ptr<Command> mergeCommand();     // merge_command.cpp

// ---- What the commands share (options.cpp) ----

// "error: MESSAGE" on err; returns kExitBadInput.
int usageError(std::ostream& err, const std::string& message);

// --frames A:B (either end may be omitted: from 0, to the end as -1); false unless 0 <= A < B.
bool parseFrames(const std::string& text, long long* from, long long* to);

// "WxH" with 1 <= W, H <= 16384.
bool parseSize(const std::string& text, int* width, int* height);

// --samples N refused: N is not a square of 1..16.
std::string samplesProblem(int samples);

// --row-labels, --column-labels: a comma list; "\," is a comma within a label.
std::vector<std::string> splitLabels(const std::string& text);

// --model: a comma list of models ("relativistic", "finite,instant", "all"), for every command
// that takes one; false with the message for an unknown name.
bool parseModelList(const std::string& text, StageOptions* options, std::string* error);

// The limits of every command that loads a scene (pipeline/stage/stage.h).
void addStageLimits(CLI::App* command, StageOptions* stage);

// Worker threads a command may ask for: TBB fails on far more (10 000 000 crashed it).
constexpr int kMaxThreads = 1024;
std::string threadsProblem(long long n);

// Runs a command; what it cannot handle itself becomes one line: out of memory (exit 3) or a broken
// invariant (exit 1), never std::terminate.
template <class Work>
int guarded(Work work, std::ostream& err) {
    try {
        return work();
    } catch (const std::bad_alloc&) {
        err << "error: out of memory (try a coarser --tolerance, fewer frames or a smaller --size)\n";
        return kExitOutputError;
    } catch (const std::exception& e) {
        err << "error: internal: " << e.what() << "\n";
        return 1;
    }
}

}  // namespace apparent
