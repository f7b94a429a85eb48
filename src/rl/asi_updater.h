// rl: Adaptive State Initialization, the trainer's side. During collection
// the running environments' visited states are captured; after the PPO
// update the critic scores them and each replaces its frame's lowest-scoring
// buffer entry if it scores higher; the kept entries are rescored in turn,
// a share of the frames per iteration, since the critic moves
// (docs/training.md, "ASI").
#ifndef MIMIC2D_RL_ASI_UPDATER_H_
#define MIMIC2D_RL_ASI_UPDATER_H_

#include <torch/torch.h>

#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "env/vec_env.h"
#include "rl/train_config.h"

namespace m2d {

class AsiUpdater {
 public:
  // Maps a batch of raw observations [N, observation_size] to values [N].
  using Critic = std::function<torch::Tensor(const torch::Tensor&)>;

  AsiUpdater(std::shared_ptr<const Character> character,
             std::shared_ptr<const TrackingReference> reference,
             std::shared_ptr<InitialStates> initial_states,
             const TrackingEnvOptions& env_options, const AsiOptions& options,
             uint64_t seed, int num_threads);

  struct CapturedState {
    int buffer = 0;  // InitialStates::BufferOf(the episode's view)
    int view = 0;    // the episode's view
    int frame = 0;
    double worst_error_px = 0.0;  // BoundedErrorPx at its capture
    SimState state;
  };
  // States offered during a rollout, with their raw observations (row i of
  // `observations` is states[i]'s).
  struct Captures {
    std::vector<CapturedState> states;
    std::vector<float> observations;
  };

  // Forgets the previous rollout's captures.
  void BeginRollout();
  // At rollout step `step`, every capture_every_steps steps: offers the
  // state and observation of every environment whose episode goes on and
  // whose worst keypoint is within max_entry_error_px (when set).
  void Capture(VecEnv& envs, int step);
  // The same for environments [begin, end) only, into `into` (a collecting
  // thread's own list; safe to call concurrently on disjoint ranges), and
  // adding such a list to this rollout's captures.
  void CaptureRange(VecEnv& envs, int step, int begin, int end,
                    Captures* into) const;
  void Add(const Captures& captures);
  // Scores the captures into the buffers, then rescores the kept entries of
  // the next frames in turn (each entry seen from a random view its buffer
  // serves): 1/rescore_every_iterations of all entries, at most
  // rescore_max_entries_per_sample x `batch_samples` (the iteration's
  // samples), observing them on `num_threads` OpenMP threads. Rescoring
  // replaces the entries beyond max_entry_error_px with their frame's
  // anchor (e.g. entries of a resumed run kept before the bound was set).
  void Update(const Critic& critic, int64_t batch_samples);
  // Entries replaced by that bound so far (this process).
  int64_t num_entries_replaced() const { return num_entries_replaced_; }
  // Entries rescored so far (this process).
  int64_t num_entries_rescored() const { return num_entries_rescored_; }

 private:
  // A buffer entry's raw observation from `view`, kept with the part of the
  // state an observation depends on (positions and velocities; the frame
  // is the entry's): rescoring observes again only entries that changed
  // or are seen from another view, since observing costs a MuJoCo forward
  // pass each (about 5 % of training time at the walk's sizes).
  struct ObservedEntry {
    int view = -1;  // -1: never observed
    std::vector<double> qpos, qvel;
    std::vector<float> raw;
    double worst_error_px = 0.0;  // BoundedErrorPx, seen from `view`

    // Whether `raw` is the observation of `state` from `view`.
    bool Holds(const SimState& state, int from_view) const {
      return view == from_view && state.qpos == qpos && state.qvel == qvel;
    }
    void Keep(const SimState& state, int from_view, const float* row, int size,
              double worst_px) {
      view = from_view;
      worst_error_px = worst_px;
      qpos = state.qpos;
      qvel = state.qvel;
      raw.assign(row, row + size);
    }
  };
  // `env`'s worst keypoint against its frame's 2D (px) when
  // max_entry_error_px bounds the entries; 0 (not measured) otherwise, so
  // that collection without the bound does no extra work.
  double BoundedErrorPx(const TrackingEnv& env) const;
  // The kept observation of entry `entry` of `frame` in `buffer`, grown on
  // first use.
  ObservedEntry& ObservedAt(int buffer, int frame, int entry);
  // Rescores the entries of the frames from the cursor on until about
  // `max_entries` are taken (whole frames; every frame at most once).
  void RescoreNextFrames(const Critic& critic, int64_t max_entries);

  AsiOptions options_;
  std::shared_ptr<const TrackingReference> reference_;
  std::shared_ptr<InitialStates> initial_states_;
  // Observe kept entries for rescoring, one per thread.
  std::vector<std::unique_ptr<TrackingEnv>> scoring_envs_;
  std::mt19937_64 rng_;  // the view each entry is rescored from
  Captures captured_;
  int64_t num_entries_replaced_ = 0;
  int64_t num_entries_rescored_ = 0;
  // The next frame to rescore, counted over every buffer's frames in order.
  int64_t rescore_cursor_ = 0;
  std::vector<std::vector<std::vector<ObservedEntry>>> observed_;  // [b][f][e]
};

}  // namespace m2d

#endif  // MIMIC2D_RL_ASI_UPDATER_H_
