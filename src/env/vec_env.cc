#include "env/vec_env.h"

#include <omp.h>

#include "common/cpus.h"
#include "common/error.h"

namespace m2d {

VecEnv::VecEnv(std::shared_ptr<const Character> character,
               std::shared_ptr<const TrackingReference> reference,
               std::shared_ptr<const InitialStates> initial_states,
               const TrackingEnvOptions& options, int num_envs, uint64_t seed,
               int num_threads) {
  if (num_envs < 1) throw ConfigError("vec env: num_envs must be >= 1");
  num_threads_ = num_threads > 0 ? num_threads : UsableCpus();
  for (int i = 0; i < num_envs; ++i) {
    envs_.push_back(std::make_unique<TrackingEnv>(
        character, reference, initial_states, options,
        seed + static_cast<uint64_t>(i)));
  }
  observation_size_ = envs_[0]->observation_size();
  action_size_ = envs_[0]->action_size();
  observations_.assign(static_cast<size_t>(num_envs) * observation_size_, 0.0f);
  final_observations_.assign(observations_.size(), 0.0f);
  actions_.assign(static_cast<size_t>(num_envs) * action_size_, 0.0f);
  rewards_.assign(num_envs, 0.0f);
  terminated_.assign(num_envs, 0);
  truncated_.assign(num_envs, 0);
  reference_ended_.assign(num_envs, 0);
  finished_flag_.assign(num_envs, 0);
  finished_stats_.resize(num_envs);
}

void VecEnv::SetReferenceNoise(const ReferenceNoise& noise) {
  for (auto& env : envs_) env->SetReferenceNoise(noise);
}

void VecEnv::Reset() {
  const int count = num_envs();
#pragma omp parallel for schedule(static) num_threads(num_threads_)
  for (int i = 0; i < count; ++i) {
    envs_[i]->Reset(observations_.data() +
                    static_cast<size_t>(i) * observation_size_);
  }
}

void VecEnv::Step(std::vector<FinishedEpisode>* finished) {
  const int count = num_envs();
  // Each environment writes only its own rows, so no locking is needed.
  // Dynamic scheduling: a step's cost varies by about 1/3 between
  // environments (contacts, resets), and every thread waits for the slowest
  // at the end of the loop (docs/benchmarks.md).
#pragma omp parallel for schedule(dynamic, 1) num_threads(num_threads_)
  for (int i = 0; i < count; ++i) StepEnv(i);
  if (finished == nullptr) return;
  for (int i = 0; i < count; ++i) {
    if (finished_flag_[i]) finished->push_back({i, finished_stats_[i]});
  }
}

void VecEnv::StepRange(int begin, int end,
                       std::vector<FinishedEpisode>* finished) {
  for (int i = begin; i < end; ++i) {
    StepEnv(i);
    if (finished != nullptr && finished_flag_[i])
      finished->push_back({i, finished_stats_[i]});
  }
}

void VecEnv::StepEnv(int i) {
  float* observation =
      observations_.data() + static_cast<size_t>(i) * observation_size_;
  StepOutcome outcome = envs_[i]->Step(
      actions_.data() + static_cast<size_t>(i) * action_size_, observation);
  rewards_[i] = outcome.reward;
  terminated_[i] = outcome.terminated;
  truncated_[i] = outcome.truncated;
  reference_ended_[i] = outcome.reference_ended;
  finished_flag_[i] = outcome.terminated || outcome.truncated;
  if (finished_flag_[i]) {
    if (outcome.truncated) {
      std::copy(observation, observation + observation_size_,
                final_observations_.data() +
                    static_cast<size_t>(i) * observation_size_);
    }
    finished_stats_[i] = envs_[i]->episode();
    envs_[i]->Reset(observation);
  }
}

}  // namespace m2d
