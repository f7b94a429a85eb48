#include "rl/asi_updater.h"

#include <omp.h>

namespace m2d {

AsiUpdater::AsiUpdater(std::shared_ptr<const Character> character,
                       std::shared_ptr<const TrackingReference> reference,
                       std::shared_ptr<InitialStates> initial_states,
                       const TrackingEnvOptions& env_options,
                       const AsiOptions& options, uint64_t seed,
                       int num_threads)
    : options_(options),
      reference_(reference),
      initial_states_(initial_states),
      rng_(seed) {
  for (int t = 0; t < std::max(1, num_threads); ++t) {
    scoring_envs_.push_back(
        std::make_unique<TrackingEnv>(character, reference, initial_states,
                                      env_options, seed + 1'000'003 + t));
  }
}

void AsiUpdater::BeginRollout() {
  captured_.clear();
  captured_observations_.clear();
}

void AsiUpdater::Capture(VecEnv& envs, int step) {
  if (step % options_.capture_every_steps != 0) return;
  const int observation_size = envs.observation_size();
  for (int i = 0; i < envs.num_envs(); ++i) {
    if (envs.terminated()[i] || envs.truncated()[i]) continue;
    TrackingEnv& env = envs.env(i);
    captured_.push_back({initial_states_->BufferOf(env.episode().view_index),
                         env.frame(), env.simulation().Save()});
    const float* row =
        envs.observations() + static_cast<size_t>(i) * observation_size;
    captured_observations_.insert(captured_observations_.end(), row,
                                  row + observation_size);
  }
}

void AsiUpdater::Update(const Critic& critic, int iteration) {
  torch::NoGradGuard no_grad;
  if (!captured_.empty()) {
    const int64_t observation_size =
        static_cast<int64_t>(captured_observations_.size() / captured_.size());
    torch::Tensor raw = torch::from_blob(
        captured_observations_.data(),
        {static_cast<int64_t>(captured_.size()), observation_size});
    torch::Tensor scores = critic(raw).to(torch::kDouble).contiguous();
    const double* score = scores.data_ptr<double>();
    for (size_t i = 0; i < captured_.size(); ++i) {
      initial_states_->buffer(captured_[i].buffer)
          .Insert(captured_[i].frame, captured_[i].state, score[i]);
    }
  }
  constexpr int kRescoreEveryIterations = 10;
  if (iteration % kRescoreEveryIterations == 0) RescoreAll(critic);
}

void AsiUpdater::RescoreAll(const Critic& critic) {
  // Outline: list every kept entry with the view it is seen from (drawn in
  // order, so runs are reproducible for any thread count), observe them in
  // parallel, score them in one critic batch, write the scores back.
  struct Slot {
    int buffer, frame, entry, view;
  };
  std::vector<Slot> slots;
  const std::vector<TrackedView>& views = reference_->views();
  for (int b = 0; b < initial_states_->num_buffers(); ++b) {
    // A state is scored as seen from one of the views its buffer serves.
    std::vector<int> buffer_views;
    for (size_t v = 0; v < views.size(); ++v) {
      if (initial_states_->BufferOf(static_cast<int>(v)) == b)
        buffer_views.push_back(static_cast<int>(v));
    }
    const StateBuffer& buffer = initial_states_->buffer(b);
    for (int f = 0; f < buffer.num_frames(); ++f) {
      for (int i = 0; i < buffer.size(f); ++i) {
        int view = buffer_views[std::uniform_int_distribution<size_t>(
            0, buffer_views.size() - 1)(rng_)];
        slots.push_back({b, f, i, view});
      }
    }
  }
  if (slots.empty()) return;

  const int observation_size = scoring_envs_[0]->observation_size();
  std::vector<float> batch(slots.size() * observation_size);
  const int num_threads = static_cast<int>(scoring_envs_.size());
#pragma omp parallel for schedule(static) num_threads(num_threads)
  for (size_t k = 0; k < slots.size(); ++k) {
    const Slot& slot = slots[k];
    scoring_envs_[omp_get_thread_num()]->ResetTo(
        slot.view, slot.frame,
        initial_states_->buffer(slot.buffer)
            .entry(slot.frame, slot.entry)
            .state,
        batch.data() + k * observation_size);
  }

  torch::Tensor raw = torch::from_blob(
      batch.data(), {static_cast<int64_t>(slots.size()), observation_size});
  torch::Tensor scores = critic(raw).to(torch::kDouble).contiguous();
  const double* score = scores.data_ptr<double>();
  for (size_t k = 0; k < slots.size(); ++k) {
    initial_states_->buffer(slots[k].buffer)
        .Rescore(slots[k].frame, slots[k].entry, score[k]);
  }
}

}  // namespace m2d
