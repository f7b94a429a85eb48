// cli: `mimic2d train` — learn a 2D tracking policy from a config, with a
// progress line, a CSV log, periodic atomic checkpoints and --resume.
#include <csignal>
#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "common/blas_kernels.h"
#include "common/error.h"
#include "rl/trainer.h"

namespace m2d::cli {
namespace {

std::atomic<bool> g_stop_requested{false};

void RequestStop(int) { g_stop_requested.store(true); }

struct TrainArgs {
  std::string config_path;
  bool resume = false;
  int max_iterations = 0;
  std::string run_dir;
  int64_t total_samples = 0;
  bool keep_checkpoints = false;
  bool list_settings = false;
};

std::string FormatDuration(double seconds) {
  if (!(seconds >= 0) || seconds > 1e8) return "--";
  int total = static_cast<int>(seconds);
  char text[32];
  std::snprintf(text, sizeof(text), "%dh%02dm%02ds", total / 3600,
                total / 60 % 60, total % 60);
  return text;
}

int RunTrain(const TrainArgs& args) {
  if (args.list_settings) {
    std::printf("%s", TrainSettingsReference().c_str());
    return 0;
  }
  if (args.config_path.empty())
    throw InputError("", "train: give a config (e.g. configs/walk.yaml)");
  TrainConfig config = LoadTrainConfig(args.config_path);
  if (!args.run_dir.empty()) config.run.run_dir = args.run_dir;
  if (args.total_samples > 0) config.run.total_samples = args.total_samples;
  if (args.keep_checkpoints) config.run.keep_checkpoints = true;
  std::printf(
      "training %s -> %s (%d envs x %d steps per iteration, %lld samples)\n",
      args.config_path.c_str(), config.run.run_dir.c_str(), config.ppo.num_envs,
      config.ppo.steps_per_env,
      static_cast<long long>(config.run.total_samples));
  std::printf("%s\n", DescribeSources(config.data.sources()).c_str());
  std::printf("BLAS: %s\n", DescribeBlas().c_str());
  // Ctrl-C / kill: finish the iteration, write a checkpoint, exit. Installed
  // before the (slow) setup, so that a stop during it is not a hard kill.
  std::signal(SIGINT, RequestStop);
  std::signal(SIGTERM, RequestStop);
  Trainer trainer(config, args.resume);

  auto report = [&](const TrainProgress& p) {
    double iteration_s = p.collect_s + p.update_s + p.asi_s;
    std::printf(
        "it %5d | %10lld samples | %6.0f samples/s (collect %2.0f%% update "
        "%2.0f%% asi %2.0f%%, %d thr%s) | "
        "return %7.2f | len %5.1f | Succ %5.1f%% | E2D %6.1f px | kl %.4f "
        "clip %4.1f%% lr %.1e | ETA %s\n",
        p.iteration, static_cast<long long>(p.samples), p.samples_per_s,
        100 * p.collect_s / iteration_s, 100 * p.update_s / iteration_s,
        100 * p.asi_s / iteration_s, p.torch_threads, p.bf16 ? " bf16" : "",
        p.mean_return, p.mean_episode_length, 100 * p.succ, p.e2d_px,
        p.approx_kl, 100 * p.clip_fraction, p.learning_rate,
        FormatDuration(p.eta_s).c_str());
    std::fflush(stdout);
  };
  TrainSummary summary =
      trainer.Run(args.max_iterations, &g_stop_requested, report);
  std::printf("%s after %d iterations; checkpoint %s\n",
              summary.interrupted ? "interrupted" : "stopped",
              summary.iterations_run, summary.checkpoint_path.c_str());
  return summary.interrupted ? 130 : 0;
}

}  // namespace

void AddTrainCommand(CLI::App& app, CommandRun* run) {
  auto args = std::make_shared<TrainArgs>();
  CLI::App* train = app.add_subcommand(
      "train", "Train a 2D tracking policy (PPO + ASI) from a YAML config");
  train
      ->add_option("config", args->config_path,
                   "Training config (YAML), e.g. configs/walk.yaml")
      ->check(CLI::ExistingFile);
  train->add_flag("--list-settings", args->list_settings,
                  "Print every config setting with its default, allowed "
                  "values and meaning (Markdown), and exit");
  train->add_flag("--resume", args->resume,
                  "Continue from <run_dir>/checkpoint.pt");
  train->add_option("--iterations", args->max_iterations,
                    "Stop after this many iterations (0: no limit)");
  train->add_option("--run-dir", args->run_dir, "Override run.run_dir");
  train->add_option("--total-samples", args->total_samples,
                    "Override run.total_samples");
  train->add_flag("--keep-checkpoints", args->keep_checkpoints,
                  "Set run.keep_checkpoints: also keep every checkpoint as "
                  "<run_dir>/checkpoints/ckpt_<samples>.pt");
  train->callback([run, args] { *run = [args] { return RunTrain(*args); }; });
}

}  // namespace m2d::cli
