#include "rl/train_benchmark.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>

#include "common/blas_kernels.h"
#include "common/error.h"
#include "env/task.h"
#include "env/vec_env.h"
#include "rl/train_config.h"
#include "rl/trainer.h"

namespace m2d {
namespace {

using Clock = std::chrono::steady_clock;

// One training setting: sequential with `torch_threads`, or overlapped.
struct Setting {
  std::string label;
  int torch_threads = 1;
  TrainingPrecision precision = TrainingPrecision::kFp32;
  CollectionMode collection = CollectionMode::kBatched;
  bool overlap = false;
};

TrainTiming MeasureTraining(TrainConfig config, const Setting& setting,
                            const TrainBenchmarkOptions& options) {
  // A scratch run directory: the bench keeps nothing it trains.
  std::string scratch = std::filesystem::temp_directory_path() /
                        ("mimic2d_bench_train_" + std::to_string(getpid()));
  config.run.run_dir = scratch;
  config.ppo.torch_threads = setting.torch_threads;
  config.ppo.training_precision = setting.precision;
  config.ppo.collection = setting.collection;
  config.ppo.overlap_update = setting.overlap;
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
      timing.wall_s += config.ppo.batch_size() / p.samples_per_s;
      timing.collect_s += p.collect_s;
      timing.update_s += p.update_s;
      timing.asi_s += p.asi_s;
    });
  }
  std::filesystem::remove_all(scratch);
  return timing;
}

// Control steps per second of the config's environments with no policy:
// Gaussian actions of the config's action sigma (what an untrained policy
// emits), episodes ending and restarting as in training.
double MeasureSimulationBound(const TrainConfig& config, int steps) {
  TrackingTask task =
      BuildTrackingTask(config.data.character_config, config.data.scene,
                        config.data.bundles, TrainingTaskOptions(config));
  VecEnv envs(task.character, task.reference, task.initial_states, config.env,
              config.ppo.num_envs, config.run.seed, config.run.env_threads);
  envs.SetReferenceNoise(config.env.training_reference_noise());
  envs.Reset();
  std::mt19937_64 rng(config.run.seed);
  std::normal_distribution<float> noise(
      0.0f, static_cast<float>(config.model.action_std));
  const int num_actions = envs.num_envs() * envs.action_size();
  std::vector<FinishedEpisode> finished;
  // Returns the seconds of the step alone: drawing the actions is not
  // simulation.
  auto step = [&] {
    for (int i = 0; i < num_actions; ++i) envs.actions()[i] = noise(rng);
    const Clock::time_point start = Clock::now();
    envs.Step(&finished);
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  for (int warmup = 0; warmup < 20; ++warmup) step();
  double simulated_s = 0.0;
  for (int t = 0; t < steps; ++t) simulated_s += step();
  return steps * static_cast<double>(envs.num_envs()) / simulated_s;
}

}  // namespace

void TrainBenchmarkOptions::Validate() const {
  if (iterations < 1) throw ConfigError("bench train: --iterations >= 1");
  if (warmup_iterations < 0)
    throw ConfigError("bench train: --warmup must be >= 0");
  if (torch_threads.empty() && !overlap) {
    throw ConfigError(
        "bench train: nothing to measure (no --torch-threads and no "
        "--overlap)");
  }
  for (int threads : torch_threads) {
    if (threads < 1) throw ConfigError("bench train: threads must be >= 1");
  }
  if (bound_steps < 1) throw ConfigError("bench train: --bound-steps >= 1");
}

void RunTrainBenchmark(const TrainBenchmarkOptions& options) {
  // Outline: the simulation-only bound, then every training setting, each
  // printed as it finishes with its ratios to the first setting and to the
  // bound.
  options.Validate();
  TrainConfig config = LoadTrainConfig(options.config_path);
  std::vector<TrainingPrecision> precisions = options.precisions;
  if (precisions.empty())
    precisions = {ResolvePrecision(config.ppo.training_precision)};
  for (TrainingPrecision precision : precisions) {
    RequirePrecisionRuns(precision, options.precisions.empty()
                                        ? "agent.training_precision"
                                        : "--precision");
  }
  std::printf(
      "bench train: %s, %d envs x %d steps = %d samples per iteration, %d "
      "env threads, BLAS: %s\n",
      options.config_path.c_str(), config.ppo.num_envs,
      config.ppo.steps_per_env, config.ppo.batch_size(), config.run.env_threads,
      DescribeBlas().c_str());
  std::printf("%d warm-up + %d timed iterations per setting\n",
              options.warmup_iterations, options.iterations);
  const double bound = MeasureSimulationBound(config, options.bound_steps);
  std::printf(
      "simulation-only bound: %.0f samples/s (the same %d environments "
      "stepped with no policy, %d env threads)\n\n",
      bound, config.ppo.num_envs, config.run.env_threads);
  std::vector<CollectionMode> collections = options.collections;
  if (collections.empty()) collections = {config.ppo.collection};
  std::vector<Setting> settings;
  for (int threads : options.torch_threads) {
    for (TrainingPrecision precision : precisions) {
      for (CollectionMode collection : collections) {
        settings.push_back({std::to_string(threads) + " " +
                                SettingName(precision) + " " +
                                SettingName(collection),
                            threads, precision, collection, false});
      }
    }
  }
  if (options.overlap) {
    settings.push_back({std::string("overlap 1+1 ") +
                            SettingName(precisions.back()) + " batched",
                        1, precisions.back(), CollectionMode::kBatched, true});
  }
  std::printf("%-27s %10s %9s %9s %9s %9s %9s\n",
              "threads precision collection", "samples/s", "collect", "update",
              "asi", "ratio", "of bound");
  double baseline = 0.0;
  for (const Setting& setting : settings) {
    const TrainTiming timing = MeasureTraining(config, setting, options);
    if (baseline == 0.0) baseline = timing.samples_per_s();
    // Shares of the wall time; with overlap collect + update exceed 100 %.
    const double wall = timing.wall_s;
    std::printf("%-27s %10.0f %8.0f%% %8.0f%% %8.0f%% %9.2f %9.2f\n",
                setting.label.c_str(), timing.samples_per_s(),
                100 * timing.collect_s / wall, 100 * timing.update_s / wall,
                100 * timing.asi_s / wall, timing.samples_per_s() / baseline,
                timing.samples_per_s() / bound);
    std::fflush(stdout);
  }
}

}  // namespace m2d
