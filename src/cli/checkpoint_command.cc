// cli: `mimic2d checkpoint slim` — a training checkpoint without its ASI
// state buffers, small enough to commit as a policy or carry through git.
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "rl/checkpoint.h"

namespace m2d::cli {
namespace {

struct SlimArgs {
  std::string input;
  std::string output;
};

int RunSlim(const SlimArgs& args) {
  const SlimCheckpointSummary summary =
      WriteSlimCheckpoint(args.input, args.output);
  std::printf(
      "wrote %s: %.1f MB (was %.1f MB; networks, optimizer and counters of "
      "%lld samples kept, ASI state buffers left out)\n",
      args.output.c_str(), summary.bytes_after / 1e6,
      summary.bytes_before / 1e6, static_cast<long long>(summary.samples));
  return 0;
}

}  // namespace

void AddCheckpointCommand(CLI::App& app, CommandRun* run) {
  CLI::App* checkpoint = app.add_subcommand(
      "checkpoint", "Convert training checkpoints (slim: without ASI buffers)");
  checkpoint->require_subcommand(1);
  auto args = std::make_shared<SlimArgs>();
  CLI::App* slim = checkpoint->add_subcommand(
      "slim",
      "Write a checkpoint without its ASI state buffers: what eval, render, "
      "generate --policy and run.init_from read; a run resumed from it "
      "refills its buffers");
  slim->add_option("checkpoint", args->input, "A train checkpoint (.pt)")
      ->required()
      ->check(CLI::ExistingFile);
  slim->add_option("-o,--output", args->output,
                   "Where to write it (may be the input)")
      ->required();
  slim->callback([run, args] { *run = [args] { return RunSlim(*args); }; });
}

}  // namespace m2d::cli
