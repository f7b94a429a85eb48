// cli: `mimic2d bench train` — end-to-end training throughput (simulation +
// inference + PPO updates + ASI) of a training config, for several LibTorch
// thread counts, each against the first as baseline (docs/benchmarks.md).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "common/blas_kernels.h"
#include "common/error.h"

#ifdef MIMIC2D_HAVE_SIM
#include "rl/trainer.h"
#endif

namespace m2d::cli {
namespace {

struct BenchTrainOptions {
  std::string config_path;
  int iterations = 10;                   // timed iterations per setting
  int warmup_iterations = 2;             // untimed iterations first
  std::vector<int> torch_threads{1, 2};  // settings measured, in order

  void Validate() const {
    if (iterations < 1) throw ConfigError("bench train: --iterations >= 1");
    if (warmup_iterations < 0)
      throw ConfigError("bench train: --warmup must be >= 0");
    if (torch_threads.empty()) {
      throw ConfigError("bench train: --torch-threads needs a value");
    }
    for (int threads : torch_threads) {
      if (threads < 1) throw ConfigError("bench train: threads must be >= 1");
    }
  }
};

#ifdef MIMIC2D_HAVE_SIM

// Totals over the timed iterations of one setting.
struct TrainTiming {
  int64_t samples = 0;
  double collect_s = 0.0, update_s = 0.0, asi_s = 0.0;

  double total_s() const { return collect_s + update_s + asi_s; }
  double samples_per_s() const { return samples / total_s(); }
};

TrainTiming MeasureTraining(TrainConfig config, int torch_threads,
                            const BenchTrainOptions& options) {
  // A scratch run directory: the bench keeps nothing it trains.
  std::string scratch = std::filesystem::temp_directory_path() /
                        ("mimic2d_bench_train_" + std::to_string(getpid()));
  config.run.run_dir = scratch;
  config.ppo.torch_threads = torch_threads;
  // Each setting is measured as given: the config's thread tuner would
  // switch counts mid-measurement (and rejects 1 thread as its maximum).
  config.ppo.adapt_torch_threads = false;
  TrainTiming timing;
  {
    Trainer trainer(config, /*resume=*/false);
    if (options.warmup_iterations > 0)
      trainer.Run(options.warmup_iterations, nullptr, nullptr);
    trainer.Run(options.iterations, nullptr, [&](const TrainProgress& p) {
      timing.samples += config.ppo.batch_size();
      timing.collect_s += p.collect_s;
      timing.update_s += p.update_s;
      timing.asi_s += p.asi_s;
    });
  }
  std::filesystem::remove_all(scratch);
  return timing;
}

int RunBenchTrain(const BenchTrainOptions& options) {
  options.Validate();
  TrainConfig config = LoadTrainConfig(options.config_path);
  std::printf(
      "bench train: %s, %d envs x %d steps = %d samples per iteration, %d "
      "env threads, BLAS: %s\n",
      options.config_path.c_str(), config.ppo.num_envs,
      config.ppo.steps_per_env, config.ppo.batch_size(), config.run.env_threads,
      DescribeBlas().c_str());
  std::printf("%d warm-up + %d timed iterations per setting\n\n",
              options.warmup_iterations, options.iterations);
  std::printf("%-14s %10s %9s %9s %9s %9s\n", "torch threads", "samples/s",
              "collect", "update", "asi", "ratio");
  double baseline = 0.0;
  for (int threads : options.torch_threads) {
    TrainTiming timing = MeasureTraining(config, threads, options);
    if (baseline == 0.0) baseline = timing.samples_per_s();
    const double total = timing.total_s();
    std::printf("%-14d %10.0f %8.0f%% %8.0f%% %8.0f%% %9.2f\n", threads,
                timing.samples_per_s(), 100 * timing.collect_s / total,
                100 * timing.update_s / total, 100 * timing.asi_s / total,
                timing.samples_per_s() / baseline);
    std::fflush(stdout);
  }
  return 0;
}

#else

int RunBenchTrain(const BenchTrainOptions&) {
  throw ConfigError("bench train: built without the simulation");
}

#endif

}  // namespace

void AddBenchTrainSubcommand(CLI::App* bench, CommandRun* run) {
  auto options = std::make_shared<BenchTrainOptions>();
  CLI::App* train = bench->add_subcommand(
      "train",
      "End-to-end training samples/s (simulation + inference + PPO update + "
      "ASI) of a config, per LibTorch thread count");
  train->add_option("config", options->config_path, "Training config (YAML)")
      ->required()
      ->check(CLI::ExistingFile);
  train
      ->add_option("--iterations", options->iterations,
                   "Timed iterations per setting")
      ->capture_default_str();
  train
      ->add_option("--warmup", options->warmup_iterations,
                   "Untimed iterations before timing")
      ->capture_default_str();
  train
      ->add_option("--torch-threads", options->torch_threads,
                   "LibTorch thread counts to measure; the first is the "
                   "baseline")
      ->delimiter(',')
      ->capture_default_str();
  train->callback(
      [run, options] { *run = [options] { return RunBenchTrain(*options); }; });
}

}  // namespace m2d::cli
