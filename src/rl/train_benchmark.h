// rl: `mimic2d bench train` — end-to-end training throughput of a config
// (simulation + policy inference + PPO update + ASI) for several LibTorch
// thread counts, arithmetic precisions and collection modes and with the
// update overlapped with collection, against the simulation-only bound measured
// in the same run: the config's own environments stepped with Gaussian actions
// and no policy, on the config's env threads (docs/benchmarks.md). No LibTorch
// in this header.
#ifndef MIMIC2D_RL_TRAIN_BENCHMARK_H_
#define MIMIC2D_RL_TRAIN_BENCHMARK_H_

#include <cstdint>
#include <string>
#include <vector>

#include "rl/train_config.h"

namespace m2d {

struct TrainBenchmarkOptions {
  std::string config_path;
  int iterations = 10;                   // timed iterations per setting
  int warmup_iterations = 2;             // untimed iterations first
  std::vector<int> torch_threads{1, 2};  // sequential settings, in order
  // Each thread count is measured at each of these (empty: the config's
  // agent.training_precision); the overlapped row uses the last.
  std::vector<TrainingPrecision> precisions;
  // ... and at each of these collection modes (empty: the config's
  // agent.collection); the overlapped row collects batched.
  std::vector<CollectionMode> collections;
  bool overlap = true;    // also measure agent.overlap_update
  int bound_steps = 200;  // control steps of the simulation-only bound
  // Throws ConfigError naming the bad option.
  void Validate() const;
};

// Totals over the timed iterations of one setting. Collection and update
// overlap in time with agent.overlap_update, so throughput is taken from
// the iterations' wall time, not the parts' sum.
struct TrainTiming {
  int64_t samples = 0;
  double wall_s = 0.0;
  double collect_s = 0.0, update_s = 0.0, asi_s = 0.0;

  double samples_per_s() const { return wall_s > 0 ? samples / wall_s : 0; }
};

// Runs every setting, then prints the table with each setting's ratio to
// the first and to the simulation-only bound.
void RunTrainBenchmark(const TrainBenchmarkOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAIN_BENCHMARK_H_
