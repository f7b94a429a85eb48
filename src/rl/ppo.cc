#include "rl/ppo.h"

#include <algorithm>

namespace m2d {

RolloutStorage::RolloutStorage(int steps, int num_envs, int observation_size,
                               int action_size)
    : observations(torch::zeros({steps, num_envs, observation_size})),
      actions(torch::zeros({steps, num_envs, action_size})),
      log_probs(torch::zeros({steps, num_envs})),
      values(torch::zeros({steps, num_envs})),
      rewards(torch::zeros({steps, num_envs})),
      dones(torch::zeros({steps, num_envs})),
      advantages(torch::zeros({steps, num_envs})),
      returns(torch::zeros({steps, num_envs})) {}

void ComputeGae(const torch::Tensor& rewards, const torch::Tensor& values,
                const torch::Tensor& dones, const torch::Tensor& last_values,
                double discount, double gae_lambda, torch::Tensor* advantages,
                torch::Tensor* returns) {
  // delta_t = r_t + gamma V(s_{t+1}) (1 - done_t) - V(s_t);
  // A_t = delta_t + gamma lambda (1 - done_t) A_{t+1}.
  const int64_t steps = rewards.size(0);
  *advantages = torch::zeros_like(rewards);
  torch::Tensor running = torch::zeros_like(last_values);
  for (int64_t t = steps - 1; t >= 0; --t) {
    torch::Tensor next_values = t == steps - 1 ? last_values : values[t + 1];
    torch::Tensor not_done = 1.0 - dones[t];
    torch::Tensor delta =
        rewards[t] + discount * next_values * not_done - values[t];
    running = delta + discount * gae_lambda * not_done * running;
    (*advantages)[t] = running;
  }
  *returns = *advantages + values;
}

double AdaptLearningRate(double learning_rate, double approx_kl,
                         const PpoOptions& options) {
  constexpr double kFactor = 1.5;
  if (approx_kl > 2.0 * options.target_kl) {
    learning_rate /= kFactor;
  } else if (approx_kl < 0.5 * options.target_kl) {
    learning_rate *= kFactor;
  }
  return std::clamp(learning_rate, options.learning_rate_min,
                    options.learning_rate_max);
}

PpoLosses PpoUpdate(ActorCritic& model, torch::optim::Optimizer& optimizer,
                    const RolloutStorage& storage, const PpoOptions& options,
                    torch::Generator& generator) {
  // Flatten [T, N] to a batch of T*N samples.
  const int64_t batch = storage.rewards.numel();
  torch::Tensor observations = storage.observations.reshape({batch, -1});
  torch::Tensor actions = storage.actions.reshape({batch, -1});
  torch::Tensor old_log_probs = storage.log_probs.reshape({batch});
  torch::Tensor advantages = storage.advantages.reshape({batch});
  torch::Tensor returns = storage.returns.reshape({batch});
  PpoLosses totals;
  int updates = 0;
  for (int epoch = 0; epoch < options.epochs; ++epoch) {
    torch::Tensor order = torch::randperm(batch, generator, torch::kLong);
    for (int64_t start = 0; start + options.minibatch_size <= batch;
         start += options.minibatch_size) {
      torch::Tensor index = order.narrow(0, start, options.minibatch_size);
      torch::Tensor obs = observations.index_select(0, index);
      torch::Tensor mean, value;
      ForwardInPrecision(model, obs, options.training_precision, &mean, &value);
      torch::Tensor log_prob =
          model->LogProb(mean, actions.index_select(0, index));

      // Normalized, clipped advantages (MimicKit clips at +-4 sigma).
      torch::Tensor advantage = advantages.index_select(0, index);
      advantage = ((advantage - advantage.mean()) / (advantage.std() + 1e-8))
                      .clamp(-options.advantage_clip, options.advantage_clip);

      // Clipped surrogate objective.
      torch::Tensor log_ratio = log_prob - old_log_probs.index_select(0, index);
      torch::Tensor ratio = log_ratio.exp();
      torch::Tensor surrogate = torch::min(
          ratio * advantage,
          ratio.clamp(1.0 - options.clip_ratio, 1.0 + options.clip_ratio) *
              advantage);
      torch::Tensor policy_loss = -surrogate.mean();

      torch::Tensor value_loss =
          0.5 * (value - returns.index_select(0, index)).pow(2).mean();
      torch::Tensor entropy = model->Entropy();
      // Keep the Gaussian's mean inside the action range [-1, 1].
      torch::Tensor bound_loss =
          torch::relu(mean.abs() - 1.0).pow(2).sum(1).mean();

      torch::Tensor loss = policy_loss +
                           options.value_loss_weight * value_loss -
                           options.entropy_weight * entropy +
                           options.action_bound_weight * bound_loss;
      optimizer.zero_grad();
      loss.backward();
      torch::nn::utils::clip_grad_norm_(model->parameters(),
                                        options.max_grad_norm);
      optimizer.step();

      torch::NoGradGuard no_grad;
      totals.policy_loss += policy_loss.item<double>();
      totals.value_loss += value_loss.item<double>();
      totals.entropy += entropy.item<double>();
      totals.approx_kl += ((ratio - 1.0) - log_ratio).mean().item<double>();
      totals.clip_fraction += ((ratio - 1.0).abs() > options.clip_ratio)
                                  .to(torch::kFloat)
                                  .mean()
                                  .item<double>();
      ++updates;
    }
  }
  if (updates > 0) {
    totals.policy_loss /= updates;
    totals.value_loss /= updates;
    totals.entropy /= updates;
    totals.approx_kl /= updates;
    totals.clip_fraction /= updates;
  }
  return totals;
}

}  // namespace m2d
