// rl: PPO, readable top to bottom — rollout storage, generalized advantage
// estimation, and the clipped-surrogate update (after CleanRL's ppo.py).
#ifndef MIMIC2D_RL_PPO_H_
#define MIMIC2D_RL_PPO_H_

#include <torch/torch.h>

#include "rl/networks.h"
#include "rl/train_config.h"

namespace m2d {

// One iteration's experience, [T, N, ...] (T steps of N environments).
struct RolloutStorage {
  RolloutStorage(int steps, int num_envs, int observation_size,
                 int action_size);

  torch::Tensor observations;  // normalized, as the networks saw them
  torch::Tensor actions;       // sampled (before the env clips them)
  torch::Tensor log_probs;
  torch::Tensor values;
  torch::Tensor rewards;  // truncation bootstrap already folded in
  torch::Tensor dones;    // 1 where the episode ended after the step
  torch::Tensor advantages;
  torch::Tensor returns;
};

// GAE(lambda): advantages and returns from rewards, values, dones and the
// value of the observation after the last step. Pure; [T, N] tensors.
void ComputeGae(const torch::Tensor& rewards, const torch::Tensor& values,
                const torch::Tensor& dones, const torch::Tensor& last_values,
                double discount, double gae_lambda, torch::Tensor* advantages,
                torch::Tensor* returns);

struct PpoLosses {
  double policy_loss = 0.0;
  double value_loss = 0.0;
  double entropy = 0.0;
  double approx_kl = 0.0;
  double clip_fraction = 0.0;
};

// rl_games' adaptive learning rate: an update whose approximate KL exceeds
// 2 x target_kl divides the rate by 1.5, one below target_kl / 2 multiplies
// it by 1.5; the result stays within [learning_rate_min, learning_rate_max].
// Pure. With a fixed sigma the KL scales as (mean step / sigma)^2, so a
// rate that suits sigma = 0.1 moves a sigma = 0.05 policy 4x as far.
double AdaptLearningRate(double learning_rate, double approx_kl,
                         const PpoOptions& options);

// `epochs` passes of shuffled minibatches over the storage.
PpoLosses PpoUpdate(ActorCritic& model, torch::optim::Optimizer& optimizer,
                    const RolloutStorage& storage, const PpoOptions& options,
                    torch::Generator& generator);

}  // namespace m2d

#endif  // MIMIC2D_RL_PPO_H_
