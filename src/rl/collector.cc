#include "rl/collector.h"

#include <cstring>

#include "rl/asi_updater.h"

namespace m2d {

RolloutCollector::RolloutCollector(VecEnv& envs, const PpoOptions& options,
                                   torch::Generator generator)
    : envs_(envs), options_(options), generator_(std::move(generator)) {}

void RolloutCollector::Collect(ActorCritic& policy, AsiUpdater* asi,
                               RolloutStorage& storage,
                               std::vector<FinishedEpisode>* finished) {
  // Outline per step: normalize observations, sample actions from the
  // Gaussian policy, step every environment in parallel, fold the value of
  // truncated episodes' last observations into their reward, offer visited
  // states to ASI. Then GAE over the batch.
  torch::NoGradGuard no_grad;
  const int num_envs = envs_.num_envs();
  const int observation_size = envs_.observation_size();
  const int action_size = envs_.action_size();
  const int steps = options_.steps_per_env;
  const double discount = options_.discount;
  auto normalized = [&](const torch::Tensor& raw) {
    return options_.normalize_observations ? policy->Normalize(raw) : raw;
  };
  if (asi) asi->BeginRollout();

  for (int t = 0; t < steps; ++t) {
    torch::Tensor raw =
        torch::from_blob(envs_.observations(), {num_envs, observation_size});
    if (options_.normalize_observations) policy->UpdateNormalizer(raw);
    torch::Tensor obs = normalized(raw);
    torch::Tensor mean, value;
    ForwardInPrecision(policy, obs, options_.training_precision, &mean, &value);
    torch::Tensor noise = at::randn({num_envs, action_size}, generator_);
    torch::Tensor action = (mean + policy->LogStd().exp() * noise).contiguous();
    storage.observations[t].copy_(obs);
    storage.actions[t].copy_(action);
    storage.log_probs[t].copy_(policy->LogProb(mean, action));
    storage.values[t].copy_(value);
    std::memcpy(envs_.actions(), action.data_ptr<float>(),
                sizeof(float) * num_envs * action_size);

    envs_.Step(finished);

    torch::Tensor reward =
        torch::from_blob(const_cast<float*>(envs_.rewards()), {num_envs})
            .clone();
    std::vector<int64_t> truncated_rows;
    for (int i = 0; i < num_envs; ++i) {
      storage.dones[t][i] =
          (envs_.terminated()[i] || envs_.truncated()[i]) ? 1.0f : 0.0f;
      if (envs_.truncated()[i]) truncated_rows.push_back(i);
    }
    if (!truncated_rows.empty()) {
      // Time limits are not failures: bootstrap with V(last observation).
      torch::Tensor rows = torch::tensor(truncated_rows, torch::kLong);
      torch::Tensor final_raw =
          torch::from_blob(const_cast<float*>(envs_.final_observations()),
                           {num_envs, observation_size})
              .index_select(0, rows);
      reward.index_add_(0, rows,
                        discount * policy->Value(normalized(final_raw)));
    }
    storage.rewards[t].copy_(reward);

    if (asi) asi->Capture(envs_, t);
  }
  torch::Tensor last_raw =
      torch::from_blob(envs_.observations(), {num_envs, observation_size});
  torch::Tensor last_values = policy->Value(normalized(last_raw));
  ComputeGae(storage.rewards, storage.values, storage.dones, last_values,
             discount, options_.gae_lambda, &storage.advantages,
             &storage.returns);
}

void CopyModelState(ActorCritic& from, ActorCritic& to, bool parameters,
                    bool buffers) {
  torch::NoGradGuard no_grad;
  if (parameters) {
    auto source = from->named_parameters();
    auto target = to->named_parameters();
    for (const auto& item : source) target[item.key()].copy_(item.value());
  }
  if (buffers) {
    auto source = from->named_buffers();
    auto target = to->named_buffers();
    for (const auto& item : source) target[item.key()].copy_(item.value());
  }
}

}  // namespace m2d
