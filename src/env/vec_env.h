// env: N tracking environments stepped in parallel, with contiguous batched
// buffers (observations, actions, rewards, flags) that a learner can wrap
// without copying (e.g. torch::from_blob).
#ifndef MIMIC2D_ENV_VEC_ENV_H_
#define MIMIC2D_ENV_VEC_ENV_H_

#include <cstdint>
#include <memory>
#include <vector>

#include "env/tracking_env.h"

namespace m2d {

// A finished episode, reported by the step that ended it.
struct FinishedEpisode {
  int env = 0;
  EpisodeStats stats;
};

class VecEnv {
 public:
  // `num_threads` <= 0 uses every CPU this process may run on (UsableCpus).
  // Environment i is seeded seed + i, so results do not depend on the thread
  // count.
  VecEnv(std::shared_ptr<const Character> character,
         std::shared_ptr<const TrackingReference> reference,
         std::shared_ptr<const InitialStates> initial_states,
         const TrackingEnvOptions& options, int num_envs, uint64_t seed,
         int num_threads);

  int num_envs() const { return static_cast<int>(envs_.size()); }
  int observation_size() const { return observation_size_; }
  int action_size() const { return action_size_; }
  const ObservationLayout& layout() const { return envs_[0]->layout(); }

  // num_envs x observation_size, row-major.
  float* observations() { return observations_.data(); }
  // num_envs x action_size; the caller writes actions here before Step().
  float* actions() { return actions_.data(); }
  const float* rewards() const { return rewards_.data(); }
  // Per env, set by the last Step(): 1 if the episode ended that way.
  const uint8_t* terminated() const { return terminated_.data(); }
  const uint8_t* truncated() const { return truncated_.data(); }
  // Of the truncated: 1 if the reference's last frame was reached (rather
  // than the time limit).
  const uint8_t* reference_ended() const { return reference_ended_.data(); }
  // For truncated envs, the observation the episode ended in (before the
  // automatic reset), so the learner can bootstrap its value.
  const float* final_observations() const { return final_observations_.data(); }

  // Resets every environment.
  void Reset();
  // Steps every environment with actions(); environments whose episode
  // ended are reset, and observations() then holds their new first
  // observation. Finished episodes are appended to `finished` (if given).
  void Step(std::vector<FinishedEpisode>* finished = nullptr);
  // Steps environments [begin, end) alone, on the calling thread, as Step()
  // does (for callers that give each thread its own share of environments).
  // Calls on disjoint ranges may run concurrently.
  void StepRange(int begin, int end, std::vector<FinishedEpisode>* finished);

  // Every environment's TrackingEnv::SetReferenceNoise (training).
  void SetReferenceNoise(const ReferenceNoise& noise);

  TrackingEnv& env(int i) { return *envs_[i]; }
  int num_threads() const { return num_threads_; }

 private:
  // Steps environment i, resets it if its episode ended (flags and stats
  // kept for the caller's report).
  void StepEnv(int i);

  std::vector<std::unique_ptr<TrackingEnv>> envs_;
  int observation_size_ = 0;
  int action_size_ = 0;
  int num_threads_ = 1;
  std::vector<float> observations_, actions_, rewards_, final_observations_;
  std::vector<uint8_t> terminated_, truncated_, reference_ended_,
      finished_flag_;
  std::vector<EpisodeStats> finished_stats_;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_VEC_ENV_H_
