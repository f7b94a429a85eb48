#include "rl/collector.h"

#include <omp.h>

#include <algorithm>
#include <cstring>
#include <exception>

#include "rl/asi_updater.h"

namespace m2d {

RolloutCollector::RolloutCollector(VecEnv& envs, const PpoOptions& options,
                                   torch::Generator generator)
    : envs_(envs), options_(options), generator_(std::move(generator)) {}

void RolloutCollector::Collect(ActorCritic& policy, AsiUpdater* asi,
                               RolloutStorage& storage,
                               std::vector<FinishedEpisode>* finished) {
  if (options_.collection == CollectionMode::kPerThread &&
      std::min(envs_.num_threads(), envs_.num_envs()) > 1) {
    CollectPerThread(policy, asi, storage, finished);
  } else {
    CollectBatched(policy, asi, storage, finished);
  }
}

void RolloutCollector::CollectBatched(ActorCritic& policy, AsiUpdater* asi,
                                      RolloutStorage& storage,
                                      std::vector<FinishedEpisode>* finished) {
  // Outline per step: normalize observations, sample actions from the
  // Gaussian policy, step every environment in parallel, fold the value of
  // truncated episodes' last observations into their reward, offer visited
  // states to ASI. Then GAE over the batch.
  torch::NoGradGuard no_grad;
  // One scope for the rollout: the weights are cast to the training
  // precision once, not at every step (PrecisionScope).
  PrecisionScope precision(options_.training_precision);
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

    RecordStepOutcome(policy, 0, num_envs, storage.rewards[t],
                      storage.dones[t]);
    if (asi) asi->Capture(envs_, t);
  }
  torch::Tensor last_raw =
      torch::from_blob(envs_.observations(), {num_envs, observation_size});
  torch::Tensor last_values =
      policy->Value(normalized(last_raw)).to(torch::kFloat);
  ComputeGae(storage.rewards, storage.values, storage.dones, last_values,
             discount, options_.gae_lambda, &storage.advantages,
             &storage.returns);
}

void RolloutCollector::CollectPerThread(
    ActorCritic& policy, AsiUpdater* asi, RolloutStorage& storage,
    std::vector<FinishedEpisode>* finished) {
  // Outline: give each env thread a contiguous share of the environments;
  // each runs the batched loop on its share alone (normalizing with the
  // statistics the rollout started with), with no barrier between steps.
  // Then merge the shares' episodes and ASI captures in thread order, let
  // the normalizer take in every step's observations in step order, and
  // compute GAE over the batch.
  const int num_envs = envs_.num_envs();
  const int observation_size = envs_.observation_size();
  const int steps = options_.steps_per_env;
  const int num_threads = std::min(envs_.num_threads(), num_envs);
  if (raw_observations_.size(0) != steps ||
      raw_observations_.size(1) != num_envs) {
    raw_observations_ = torch::empty({steps, num_envs, observation_size});
  }
  while (static_cast<int>(shard_generators_.size()) < num_threads) {
    // Streams derived from the run's seed, one per thread, so that a run
    // is reproducible for a given thread count.
    const uint64_t seed = generator_.current_seed() +
                          1'000'033ull * (shard_generators_.size() + 1);
    shard_generators_.push_back(at::make_generator<at::CPUGeneratorImpl>(seed));
  }
  if (asi) asi->BeginRollout();
  torch::Tensor last_values = torch::empty({num_envs});
  std::vector<std::vector<FinishedEpisode>> shard_finished(num_threads);
  std::vector<AsiUpdater::Captures> shard_captures(num_threads);
  std::vector<std::exception_ptr> shard_error(num_threads);

#pragma omp parallel num_threads(num_threads)
  {
    // Shards are independent, so a thread may run several in turn should
    // OpenMP grant fewer threads than asked.
    for (int k = omp_get_thread_num(); k < num_threads;
         k += omp_get_num_threads()) {
      try {
        Shard shard{num_envs * k / num_threads,
                    num_envs * (k + 1) / num_threads, shard_generators_[k]};
        CollectShard(policy, asi, shard, storage, last_values,
                     &shard_finished[k], &shard_captures[k]);
      } catch (...) {
        shard_error[k] = std::current_exception();  // rethrown below
      }
    }
  }
  for (const std::exception_ptr& error : shard_error) {
    if (error) std::rethrow_exception(error);
  }

  torch::NoGradGuard no_grad;
  for (int k = 0; k < num_threads; ++k) {
    if (finished) {
      finished->insert(finished->end(), shard_finished[k].begin(),
                       shard_finished[k].end());
    }
    if (asi) asi->Add(shard_captures[k]);
  }
  if (options_.normalize_observations) {
    for (int t = 0; t < steps; ++t)
      policy->UpdateNormalizer(raw_observations_[t]);
  }
  ComputeGae(storage.rewards, storage.values, storage.dones, last_values,
             options_.discount, options_.gae_lambda, &storage.advantages,
             &storage.returns);
}

void RolloutCollector::CollectShard(ActorCritic& policy, AsiUpdater* asi,
                                    Shard& shard, RolloutStorage& storage,
                                    torch::Tensor& last_values,
                                    std::vector<FinishedEpisode>* finished,
                                    AsiUpdater::Captures* captures) {
  // Grad mode and autocast are per thread: set both here. LibTorch runs
  // single-threaded inside this OpenMP region.
  torch::NoGradGuard no_grad;
  PrecisionScope precision(options_.training_precision);
  const int64_t begin = shard.begin, rows = shard.end - shard.begin;
  const int observation_size = envs_.observation_size();
  const int action_size = envs_.action_size();
  auto normalized = [&](const torch::Tensor& raw) {
    return options_.normalize_observations ? policy->Normalize(raw) : raw;
  };
  auto observed_rows = [&] {
    return torch::from_blob(envs_.observations() + begin * observation_size,
                            {rows, observation_size});
  };
  for (int t = 0; t < options_.steps_per_env; ++t) {
    torch::Tensor raw = observed_rows();
    raw_observations_[t].narrow(0, begin, rows).copy_(raw);
    torch::Tensor obs = normalized(raw);
    torch::Tensor mean, value;
    ForwardInPrecision(policy, obs, options_.training_precision, &mean, &value);
    torch::Tensor noise = at::randn({rows, action_size}, shard.generator);
    torch::Tensor action = (mean + policy->LogStd().exp() * noise).contiguous();
    storage.observations[t].narrow(0, begin, rows).copy_(obs);
    storage.actions[t].narrow(0, begin, rows).copy_(action);
    storage.log_probs[t]
        .narrow(0, begin, rows)
        .copy_(policy->LogProb(mean, action));
    storage.values[t].narrow(0, begin, rows).copy_(value);
    std::memcpy(envs_.actions() + begin * action_size, action.data_ptr<float>(),
                sizeof(float) * rows * action_size);

    envs_.StepRange(shard.begin, shard.end, finished);

    RecordStepOutcome(policy, shard.begin, shard.end, storage.rewards[t],
                      storage.dones[t]);
    if (asi) asi->CaptureRange(envs_, t, shard.begin, shard.end, captures);
  }
  last_values.narrow(0, begin, rows)
      .copy_(policy->Value(normalized(observed_rows())));
}

void RolloutCollector::RecordStepOutcome(ActorCritic& policy, int begin,
                                         int end, torch::Tensor rewards,
                                         torch::Tensor dones) {
  // rewards and dones: this step's [num_envs] rows of the storage.
  float* reward = rewards.data_ptr<float>();
  float* done = dones.data_ptr<float>();
  // Outline: copy rewards and done flags; then the rows cut by a time limit
  // (not failures) get gamma * V(last observation). A reference's end is
  // bootstrapped only when the options say so.
  std::vector<int64_t> bootstrapped_rows;
  for (int i = begin; i < end; ++i) {
    reward[i] = envs_.rewards()[i];
    done[i] = (envs_.terminated()[i] || envs_.truncated()[i]) ? 1.0f : 0.0f;
    const bool bootstrap =
        envs_.truncated()[i] &&
        (options_.bootstrap_at_reference_end || !envs_.reference_ended()[i]);
    if (bootstrap) bootstrapped_rows.push_back(i);
  }
  if (bootstrapped_rows.empty()) return;
  torch::Tensor final_raw =
      torch::from_blob(const_cast<float*>(envs_.final_observations()),
                       {envs_.num_envs(), envs_.observation_size()})
          .index_select(0, torch::tensor(bootstrapped_rows, torch::kLong));
  torch::Tensor final_value =
      policy
          ->Value(options_.normalize_observations ? policy->Normalize(final_raw)
                                                  : final_raw)
          .to(torch::kFloat)
          .contiguous();
  const float* value = final_value.data_ptr<float>();
  for (size_t r = 0; r < bootstrapped_rows.size(); ++r) {
    reward[bootstrapped_rows[r]] +=
        static_cast<float>(options_.discount) * value[r];
  }
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
