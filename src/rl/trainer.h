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
#include "rl/training_log.h"

namespace m2d {

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

  // Seconds of one iteration and of its parts (collection and update run
  // at once with agent.overlap_update).
  struct IterationTiming {
    double iteration_s = 0.0;
    double collect_s = 0.0, update_s = 0.0, asi_s = 0.0;
  };

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_TRAINER_H_
