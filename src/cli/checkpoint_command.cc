// cli: `mimic2d checkpoint info|slim|average` — what a training checkpoint
// holds, the same checkpoint without its ASI state buffers (small enough to
// commit as a policy or carry through git), and the mean of a line's
// checkpoints.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

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

struct AverageArgs {
  std::vector<std::string> inputs;
  std::string output;
};

int RunAverage(const AverageArgs& args) {
  const AveragedCheckpointSummary summary =
      AverageCheckpoints(args.inputs, args.output);
  std::printf(
      "wrote %s: the mean of %d checkpoints' networks and normalizers "
      "(%lld to %lld samples); optimizer, counters and config of the newest, "
      "no ASI state buffers\n",
      args.output.c_str(), summary.num_averaged,
      static_cast<long long>(summary.first_samples),
      static_cast<long long>(summary.last_samples));
  return 0;
}

struct InfoArgs {
  std::string input;
};

// "[512, 256, 256]"
std::string Widths(const std::vector<int>& widths) {
  std::string text = "[";
  for (size_t i = 0; i < widths.size(); ++i) {
    text += (i ? ", " : "") + std::to_string(widths[i]);
  }
  return text + "]";
}

int RunInfo(const InfoArgs& args) {
  const CheckpointInfo info = ReadCheckpointInfo(args.input);
  const TrainConfig& config = info.config;
  const double hours = info.counters.wall_time_s / 3600.0;
  std::printf("%s: %.1f MB\n", args.input.c_str(), info.bytes / 1e6);
  std::printf(
      "  trained: %lld samples in %d iterations, %.2f h of training wall "
      "time, learning rate %.3g\n",
      static_cast<long long>(info.counters.samples), info.counters.iteration,
      hours, info.counters.learning_rate);
  std::printf("  data: %zu bundle(s)%s%s, initial states %s, cameras %s\n",
              config.data.bundles.size(),
              config.data.bundles.empty() ? "" : " from ",
              config.data.bundles.empty() ? "" : config.data.bundles[0].c_str(),
              SettingName(config.data.initial_states),
              SettingName(config.data.cameras));
  std::printf(
      "  task: target %s, %d future frames, %d points per frame, %d "
      "actions\n",
      SettingName(config.env.target), info.layout.num_future_frames,
      info.layout.num_points, info.action_size);
  std::printf(
      "  networks: phi %s -> %d, policy %s, critic %s, action std %g\n",
      Widths(config.model.encoder_hidden).c_str(),
      config.model.encoder_features, Widths(config.model.policy_hidden).c_str(),
      Widths(config.model.critic_hidden).c_str(), config.model.action_std);
  if (info.layout.critic_only_size > 0) {
    std::printf(
        "  asymmetric critic: %d critic-only inputs (the camera and the 3D "
        "reference of the initial states, %s); the policy does not read "
        "them\n",
        info.layout.critic_only_size, SettingName(config.data.initial_states));
  }
  if (info.num_state_buffers > 0) {
    std::printf("  ASI buffers: %d holding %lld states\n",
                info.num_state_buffers,
                static_cast<long long>(info.num_buffered_states));
  } else {
    std::printf(
        "  ASI buffers: none (slim, or ASI off); train --resume refills them "
        "from the bundles\n");
  }
  std::printf("  run: %s (seed %llu)\n", config.run.run_dir.c_str(),
              static_cast<unsigned long long>(config.run.seed));
  if (!config.run.init_from.empty()) {
    std::printf("  fine-tuned from: %s (the samples above count from there)\n",
                config.run.init_from.c_str());
  }
  return 0;
}

}  // namespace

void AddCheckpointCommand(CLI::App& app, CommandRun* run) {
  CLI::App* checkpoint = app.add_subcommand(
      "checkpoint",
      "Inspect or convert training checkpoints (info: what one holds; slim: "
      "without ASI buffers; average: the mean of a line's checkpoints)");
  checkpoint->require_subcommand(1);
  auto info_args = std::make_shared<InfoArgs>();
  CLI::App* info = checkpoint->add_subcommand(
      "info",
      "Print what a checkpoint holds: samples trained, data and sources, "
      "networks, ASI buffers");
  info->add_option("checkpoint", info_args->input, "A train checkpoint (.pt)")
      ->required()
      ->check(CLI::ExistingFile);
  info->callback(
      [run, info_args] { *run = [info_args] { return RunInfo(*info_args); }; });
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
      ->check(WritableFile())
      ->required();
  slim->callback([run, args] { *run = [args] { return RunSlim(*args); }; });
  auto average_args = std::make_shared<AverageArgs>();
  CLI::App* average = checkpoint->add_subcommand(
      "average",
      "Write the element-wise mean of checkpoints of one line (same networks "
      "and layout): networks and observation normalizers averaged; "
      "optimizer, counters and config of the newest (most samples); no ASI "
      "buffers");
  average
      ->add_option("checkpoints", average_args->inputs,
                   "Two or more train checkpoints (.pt) of one line, in any "
                   "order")
      ->required()
      ->expected(2, -1)
      ->check(CLI::ExistingFile);
  average->add_option("-o,--output", average_args->output, "Where to write it")
      ->check(WritableFile())
      ->required();
  average->callback([run, average_args] {
    *run = [average_args] { return RunAverage(*average_args); };
  });
}

}  // namespace m2d::cli
