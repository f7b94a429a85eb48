// rl: collecting one batch of experience. The behavior policy acts in every
// environment for `steps_per_env` steps; the batch (normalized
// observations, sampled actions and their log-probabilities, values,
// rewards with time limits bootstrapped) and its GAE advantages land in a
// RolloutStorage; visited states are offered to ASI.
#ifndef MIMIC2D_RL_COLLECTOR_H_
#define MIMIC2D_RL_COLLECTOR_H_

#include <torch/torch.h>

#include <vector>

#include "env/vec_env.h"
#include "rl/asi_updater.h"
#include "rl/networks.h"
#include "rl/ppo.h"
#include "rl/train_config.h"

namespace m2d {

class RolloutCollector {
 public:
  // `generator` draws the Gaussian action noise (its own stream, so that a
  // concurrent update's shuffling does not share it).
  RolloutCollector(VecEnv& envs, const PpoOptions& options,
                   torch::Generator generator);

  // Fills `storage` acting with `policy` (whose observation normalizer is
  // updated when options.normalize_observations); `asi` (may be null)
  // captures visited states; episodes that end are appended to `finished`.
  // options.collection chooses how the env threads are used.
  void Collect(ActorCritic& policy, AsiUpdater* asi, RolloutStorage& storage,
               std::vector<FinishedEpisode>* finished);
  // The arithmetic of the next collections (the trainer's speed tuner may
  // change it between iterations).
  void set_precision(TrainingPrecision precision) {
    options_.training_precision = precision;
  }

 private:
  // One thread's share of the environments under kPerThread.
  struct Shard {
    int begin = 0, end = 0;  // environments [begin, end)
    torch::Generator generator;
  };
  void CollectBatched(ActorCritic& policy, AsiUpdater* asi,
                      RolloutStorage& storage,
                      std::vector<FinishedEpisode>* finished);
  void CollectPerThread(ActorCritic& policy, AsiUpdater* asi,
                        RolloutStorage& storage,
                        std::vector<FinishedEpisode>* finished);
  void CollectShard(ActorCritic& policy, AsiUpdater* asi, Shard& shard,
                    RolloutStorage& storage, torch::Tensor& last_values,
                    std::vector<FinishedEpisode>* finished,
                    AsiUpdater::Captures* captures);
  // After a step of environments [begin, end): their rewards (time-limit
  // truncations bootstrapped with the critic) and done flags into this
  // step's rows of the storage.
  void RecordStepOutcome(ActorCritic& policy, int begin, int end,
                         torch::Tensor rewards, torch::Tensor dones);

  VecEnv& envs_;
  PpoOptions options_;
  torch::Generator generator_;                      // kBatched's action noise
  std::vector<torch::Generator> shard_generators_;  // kPerThread's, per thread
  // kPerThread: every step's raw observations, for the normalizer after
  // the rollout. [steps, num_envs, observation_size].
  torch::Tensor raw_observations_ = torch::empty({0, 0, 0});
};

// Copies `from`'s parameters (and, with `buffers`, its buffers: the
// observation normalizer) into `to`, a model of the same layout.
void CopyModelState(ActorCritic& from, ActorCritic& to, bool parameters,
                    bool buffers);

}  // namespace m2d

#endif  // MIMIC2D_RL_COLLECTOR_H_
