// rl: the training loop — collect rollouts in parallel environments, update
// with PPO, refresh the ASI state buffers, log, checkpoint atomically, and
// resume. No LibTorch in this header (the CLI includes it).
#ifndef MIMIC2D_RL_TRAINER_H_
#define MIMIC2D_RL_TRAINER_H_

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "rl/train_config.h"

namespace m2d {

// One row of the training log (train_log.csv).
struct TrainProgress {
  int iteration = 0;
  int64_t samples = 0;
  double wall_time_s = 0.0;    // across resumed runs
  double samples_per_s = 0.0;  // end to end, this iteration
  double mean_return = 0.0;    // finished episodes of this iteration
  double mean_episode_length = 0.0;
  double succ = 0.0;    // fraction not ended by early exit
  double e2d_px = 0.0;  // mean 2D error of those episodes
  double policy_loss = 0.0, value_loss = 0.0, entropy = 0.0;
  double approx_kl = 0.0;      // PPO update: mean KL(old || new) estimate
  double clip_fraction = 0.0;  // and the share of clipped ratios
  double learning_rate = 0.0;
  double collect_s = 0.0, update_s = 0.0, asi_s = 0.0;  // time split
  int torch_threads = 1;  // LibTorch threads this iteration ran with
};

struct TrainSummary {
  TrainProgress last;
  int iterations_run = 0;  // in this invocation
  bool interrupted = false;
  std::string checkpoint_path;
};

class Trainer {
 public:
  // Builds everything the config names (character, bundles, envs, model).
  // With `resume`, continues from <run_dir>/checkpoint.pt.
  Trainer(const TrainConfig& config, bool resume);
  ~Trainer();

  // Trains until total_samples, `max_iterations` (if > 0), or `*stop`
  // becomes true (e.g. SIGINT); writes a final checkpoint either way.
  TrainSummary Run(
      int max_iterations, const std::atomic<bool>* stop,
      const std::function<void(const TrainProgress&)>& on_progress);

  // Writes the checkpoint now (e.g. of the untrained policy, as a baseline).
  void SaveCheckpoint();
  const std::string& checkpoint_path() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAINER_H_
