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
#include "rl/networks.h"
#include "rl/ppo.h"
#include "rl/train_config.h"

namespace m2d {

class AsiUpdater;

class RolloutCollector {
 public:
  // `generator` draws the Gaussian action noise (its own stream, so that a
  // concurrent update's shuffling does not share it).
  RolloutCollector(VecEnv& envs, const PpoOptions& options,
                   torch::Generator generator);

  // Fills `storage` acting with `policy` (whose observation normalizer is
  // updated when options.normalize_observations); `asi` (may be null)
  // captures visited states; episodes that end are appended to `finished`.
  void Collect(ActorCritic& policy, AsiUpdater* asi, RolloutStorage& storage,
               std::vector<FinishedEpisode>* finished);

 private:
  VecEnv& envs_;
  PpoOptions options_;
  torch::Generator generator_;
};

// Copies `from`'s parameters (and, with `buffers`, its buffers: the
// observation normalizer) into `to`, a model of the same layout.
void CopyModelState(ActorCritic& from, ActorCritic& to, bool parameters,
                    bool buffers);

}  // namespace m2d

#endif  // MIMIC2D_RL_COLLECTOR_H_
