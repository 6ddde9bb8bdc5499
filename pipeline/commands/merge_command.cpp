// `apparent merge`: its options, checked into MergeSettings, then the shards' merge of
// pipeline/run/shards.h.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "pipeline/commands/command.h"
#include "pipeline/run/shards.h"

namespace apparent {

// ---- The command: `apparent merge` ----

namespace {

class MergeCommand : public Command {
public:
    CLI::App* add(CLI::App* app) override {
        cmd = app->add_subcommand(
            "merge", "Assemble DIR/<model>.glb from the shards of 'render --shard I/N --out DIR' (byte-identical to one process)");
        cmd->add_option("dir", ms.out_dir, "The --out folder of the shards (reads DIR/shards)")->required();
        cmd->add_option("--max-output-bytes", ms.max_output_bytes,
                        "Stop with exit code 3 before the .glb files would exceed this many bytes in all (0: no limit)")
            ->capture_default_str();
        cmd->add_flag("--quiet,-q", ms.quiet, "No summary");
        cmd->add_flag("--verbose,-v", ms.verbose, "Export precision, as render --verbose");
        cmd->footer(
            "Refuses (exit code 2, one line) a shard that is missing, duplicated, incomplete, or made from another scene,\n"
            "other meshes or other output options (each shard holds a fingerprint of them). The shards stay in DIR/shards.");
        return cmd;
    }

    int run(std::ostream& out, std::ostream& err) override {
        if (ms.max_output_bytes < 0) return usageError(err, "--max-output-bytes: must be positive, or 0 for no limit");
        return guarded([&] { return merge(ms, out, err); }, err);
    }

private:
    MergeSettings ms;
    CLI::App* cmd = nullptr;
};

}  // namespace

std::unique_ptr<Command> mergeCommand() { return std::make_unique<MergeCommand>(); }

}  // namespace apparent
