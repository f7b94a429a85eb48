#include "rl/asi_updater.h"

#include <omp.h>

#include <algorithm>

#include "env/reward.h"

namespace m2d {
namespace {

// The worst keypoint's distance (px) between `env`'s character, as the
// camera of its episode's view sees it, and the 2D of its current frame.
double WorstKeypointErrorPx(const TrackingEnv& env) {
  const int num_keypoints =
      env.simulation().character().keypoint_layout().num_keypoints();
  return MeasureReprojection(env.projected_px().data(), env.in_front(),
                             env.view().frame(env.frame()), num_keypoints)
      .max_px;
}

// Scores that place an entry below any critic value: one beyond the bound
// (replaced first), and the anchor put in its place until the next
// rescoring gives it its own.
constexpr double kEntryOffReferenceScore = -1e30;
constexpr double kAnchorPlaceholderScore = -1e29;

}  // namespace

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

double AsiUpdater::BoundedErrorPx(const TrackingEnv& env) const {
  return options_.max_entry_error_px > 0 ? WorstKeypointErrorPx(env) : 0.0;
}

void AsiUpdater::BeginRollout() {
  captured_.states.clear();
  captured_.observations.clear();
}

void AsiUpdater::Capture(VecEnv& envs, int step) {
  CaptureRange(envs, step, 0, envs.num_envs(), &captured_);
}

void AsiUpdater::CaptureRange(VecEnv& envs, int step, int begin, int end,
                              Captures* into) const {
  if (step % options_.capture_every_steps != 0) return;
  const int observation_size = envs.observation_size();
  for (int i = begin; i < end; ++i) {
    if (envs.terminated()[i] || envs.truncated()[i]) continue;
    TrackingEnv& env = envs.env(i);
    const double worst_px = BoundedErrorPx(env);
    if (!(worst_px <= options_.max_entry_error_px)) continue;
    into->states.push_back({initial_states_->BufferOf(env.episode().view_index),
                            env.episode().view_index, env.frame(), worst_px,
                            env.simulation().Save()});
    const float* row =
        envs.observations() + static_cast<size_t>(i) * observation_size;
    into->observations.insert(into->observations.end(), row,
                              row + observation_size);
  }
}

void AsiUpdater::Add(const Captures& captures) {
  captured_.states.insert(captured_.states.end(), captures.states.begin(),
                          captures.states.end());
  captured_.observations.insert(captured_.observations.end(),
                                captures.observations.begin(),
                                captures.observations.end());
}

void AsiUpdater::Update(const Critic& critic, int64_t batch_samples) {
  torch::NoGradGuard no_grad;
  const std::vector<CapturedState>& states = captured_.states;
  if (!states.empty()) {
    const int64_t observation_size =
        static_cast<int64_t>(captured_.observations.size() / states.size());
    torch::Tensor raw = torch::from_blob(
        captured_.observations.data(),
        {static_cast<int64_t>(states.size()), observation_size});
    torch::Tensor scores = critic(raw).to(torch::kDouble).contiguous();
    const double* score = scores.data_ptr<double>();
    for (size_t i = 0; i < states.size(); ++i) {
      StateBuffer& buffer = initial_states_->buffer(states[i].buffer);
      if (!buffer.Insert(states[i].frame, states[i].state, score[i])) continue;
      // Keep what the capture observed, for rescoring: find the entry the
      // state went into.
      const int frame = states[i].frame;
      for (int e = 0; e < buffer.size(frame); ++e) {
        const SimState& kept = buffer.entry(frame, e).state;
        if (kept.qpos != states[i].state.qpos ||
            kept.qvel != states[i].state.qvel)
          continue;
        ObservedAt(states[i].buffer, frame, e)
            .Keep(kept, states[i].view,
                  captured_.observations.data() + i * observation_size,
                  static_cast<int>(observation_size), states[i].worst_error_px);
        break;
      }
    }
  }
  // This iteration's share of the rescoring: a sweep every
  // rescore_every_iterations, unless the cap per sample binds.
  int64_t num_entries = 0;
  for (int b = 0; b < initial_states_->num_buffers(); ++b) {
    const StateBuffer& buffer = initial_states_->buffer(b);
    for (int f = 0; f < buffer.num_frames(); ++f) num_entries += buffer.size(f);
  }
  int64_t share = (num_entries + options_.rescore_every_iterations - 1) /
                  options_.rescore_every_iterations;
  if (options_.rescore_max_entries_per_sample > 0) {
    share = std::min<int64_t>(
        share,
        std::max<int64_t>(
            1, static_cast<int64_t>(options_.rescore_max_entries_per_sample *
                                    static_cast<double>(batch_samples))));
  }
  RescoreNextFrames(critic, share);
}

AsiUpdater::ObservedEntry& AsiUpdater::ObservedAt(int buffer, int frame,
                                                  int entry) {
  if (observed_.size() <= static_cast<size_t>(buffer))
    observed_.resize(initial_states_->num_buffers());
  auto& frames = observed_[buffer];
  if (frames.size() <= static_cast<size_t>(frame))
    frames.resize(initial_states_->buffer(buffer).num_frames());
  auto& entries = frames[frame];
  if (entries.size() <= static_cast<size_t>(entry))
    entries.resize(
        initial_states_->buffer(buffer).options().capacity_per_frame);
  return entries[entry];
}

void AsiUpdater::RescoreNextFrames(const Critic& critic, int64_t max_entries) {
  // Outline: from the cursor on, list whole frames' kept entries with the
  // view each is seen from (drawn in order, so runs are reproducible for
  // any thread count) until about max_entries are listed, observe in
  // parallel those not observed so from that view before, score them all
  // in one critic batch, write the scores back.
  struct Slot {
    int buffer, frame, entry, view;
  };
  const int num_buffers = initial_states_->num_buffers();
  int64_t num_frames = 0;
  for (int b = 0; b < num_buffers; ++b)
    num_frames += initial_states_->buffer(b).num_frames();
  if (num_frames == 0 || max_entries <= 0) return;
  // The views each buffer serves: a state is scored as seen from one.
  const std::vector<TrackedView>& views = reference_->views();
  std::vector<std::vector<int>> buffer_views(num_buffers);
  for (size_t v = 0; v < views.size(); ++v)
    buffer_views[initial_states_->BufferOf(static_cast<int>(v))].push_back(
        static_cast<int>(v));
  // The cursor's buffer and frame.
  rescore_cursor_ %= num_frames;
  int b = 0;
  int64_t f = rescore_cursor_;
  while (f >= initial_states_->buffer(b).num_frames())
    f -= initial_states_->buffer(b++).num_frames();
  std::vector<Slot> slots;
  int64_t taken = 0;  // frames
  for (; taken < num_frames && static_cast<int64_t>(slots.size()) < max_entries;
       ++taken) {
    const StateBuffer& buffer = initial_states_->buffer(b);
    for (int i = 0; i < buffer.size(static_cast<int>(f)); ++i) {
      const std::vector<int>& served = buffer_views[b];
      int view = served[std::uniform_int_distribution<size_t>(
          0, served.size() - 1)(rng_)];
      slots.push_back({b, static_cast<int>(f), i, view});
    }
    // The next frame, across buffers (and buffers without frames).
    ++f;
    while (f >= initial_states_->buffer(b).num_frames()) {
      f = 0;
      b = (b + 1) % num_buffers;
    }
  }
  rescore_cursor_ = (rescore_cursor_ + taken) % num_frames;
  if (slots.empty()) return;
  num_entries_rescored_ += static_cast<int64_t>(slots.size());

  const int observation_size = scoring_envs_[0]->observation_size();
  std::vector<float> batch(slots.size() * observation_size);
  // Sized here, so that the parallel loop only writes its own entries.
  for (const Slot& slot : slots)
    ObservedAt(slot.buffer, slot.frame, slot.entry);
  const int num_threads = static_cast<int>(scoring_envs_.size());
#pragma omp parallel for schedule(dynamic, 64) num_threads(num_threads)
  for (size_t k = 0; k < slots.size(); ++k) {
    const Slot& slot = slots[k];
    const SimState& state = initial_states_->buffer(slot.buffer)
                                .entry(slot.frame, slot.entry)
                                .state;
    ObservedEntry& observed = observed_[slot.buffer][slot.frame][slot.entry];
    float* row = batch.data() + k * observation_size;
    if (observed.Holds(state, slot.view)) {
      std::copy(observed.raw.begin(), observed.raw.end(), row);
      continue;
    }
    TrackingEnv& env = *scoring_envs_[omp_get_thread_num()];
    env.ResetTo(slot.view, slot.frame, state, row);
    observed.Keep(state, slot.view, row, observation_size, BoundedErrorPx(env));
  }

  torch::Tensor raw = torch::from_blob(
      batch.data(), {static_cast<int64_t>(slots.size()), observation_size});
  torch::Tensor scores = critic(raw).to(torch::kDouble).contiguous();
  const double* score = scores.data_ptr<double>();
  const double bound_px = options_.max_entry_error_px;
  for (size_t k = 0; k < slots.size(); ++k) {
    const Slot& slot = slots[k];
    StateBuffer& buffer = initial_states_->buffer(slot.buffer);
    const double worst_px =
        observed_[slot.buffer][slot.frame][slot.entry].worst_error_px;
    const SimState* anchor = buffer.anchor(slot.frame);
    auto is_anchor = [&] {
      const SimState& state = buffer.entry(slot.frame, slot.entry).state;
      return anchor != nullptr && state.qpos == anchor->qpos &&
             state.qvel == anchor->qvel;
    };
    // The anchor stays whatever its error: it is the frame's own start.
    if (bound_px <= 0 || worst_px <= bound_px || is_anchor()) {
      buffer.Rescore(slot.frame, slot.entry, score[k]);
      continue;
    }
    // Off the reference: the lowest score, then (with an anchor) the
    // anchor in its place, which Insert puts in the lowest entry.
    buffer.Rescore(slot.frame, slot.entry, kEntryOffReferenceScore);
    ++num_entries_replaced_;
    if (anchor != nullptr)
      buffer.Insert(slot.frame, *anchor, kAnchorPlaceholderScore);
  }
}

}  // namespace m2d
