// rl: Adaptive State Initialization, the trainer's side. During collection
// the running environments' visited states are captured; after the PPO
// update the critic scores them and each replaces its frame's lowest-scoring
// buffer entry if it scores higher; every few iterations all kept entries
// are rescored, since the critic moves (docs/training.md, "ASI").
#ifndef MIMIC2D_RL_ASI_UPDATER_H_
#define MIMIC2D_RL_ASI_UPDATER_H_

#include <torch/torch.h>

#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "env/vec_env.h"
#include "rl/train_config.h"

namespace m2d {

class AsiUpdater {
 public:
  // Maps a batch of raw observations [N, observation_size] to values [N].
  using Critic = std::function<torch::Tensor(const torch::Tensor&)>;

  AsiUpdater(std::shared_ptr<const Character> character,
             std::shared_ptr<const TrackingReference> reference,
             std::shared_ptr<InitialStates> initial_states,
             const TrackingEnvOptions& env_options, const AsiOptions& options,
             uint64_t seed, int num_threads);

  // Forgets the previous rollout's captures.
  void BeginRollout();
  // At rollout step `step`, every capture_every_steps steps: offers the
  // state and observation of every environment whose episode goes on.
  void Capture(VecEnv& envs, int step);
  // Scores the captures into the buffers; on every 10th `iteration` also
  // rescores every kept entry (each seen from a random view its buffer
  // serves), observing them on `num_threads` OpenMP threads.
  void Update(const Critic& critic, int iteration);

 private:
  struct CapturedState {
    int buffer = 0;  // InitialStates::BufferOf(the episode's view)
    int frame = 0;
    SimState state;
  };
  void RescoreAll(const Critic& critic);

  AsiOptions options_;
  std::shared_ptr<const TrackingReference> reference_;
  std::shared_ptr<InitialStates> initial_states_;
  // Observe kept entries for rescoring, one per thread.
  std::vector<std::unique_ptr<TrackingEnv>> scoring_envs_;
  std::mt19937_64 rng_;  // the view each entry is rescored from
  std::vector<CapturedState> captured_;
  std::vector<float> captured_observations_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_ASI_UPDATER_H_
