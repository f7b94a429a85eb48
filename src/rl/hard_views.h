// rl: hard-view sampling. A tracker of many clips spends its samples
// uniformly over the views it learns from, long after it holds the easy
// ones; here episodes start on a view in proportion to how likely a rollout
// of the whole view is to fail, estimated on line from the training
// episodes' early exits (PHC's hard-negative mining, without its periodic
// evaluation). docs/training.md, "Hard-view sampling".
#ifndef MIMIC2D_RL_HARD_VIEWS_H_
#define MIMIC2D_RL_HARD_VIEWS_H_

#include <string>
#include <vector>

#include "env/reference.h"
#include "env/vec_env.h"
#include "rl/train_config.h"

namespace m2d {

// A view's training experience, decayed with age: steps simulated,
// episodes ended by early exit (or divergence) over them, and episodes
// ended in all.
struct ViewFailureRecord {
  double steps = 0.0;
  double failures = 0.0;
  double episodes = 0.0;
};

// Probability that a rollout of `num_frames` frames fails when early exits
// come at the record's rate per step (a constant hazard h = failures /
// steps): 1 - exp(-h (num_frames - 1)). Negative when the record holds no
// steps (unknown).
double FullRolloutFailure(const ViewFailureRecord& record, int num_frames);

// Early exits per step simulated (the constant hazard h); negative when the
// record holds no steps (unknown).
double FailureHazard(const ViewFailureRecord& record);

// The hazard over the mean episode length (steps per episode ended): starts
// in proportion to it give each view samples (starts x steps per episode)
// in proportion to its hazard. Negative when the record holds no episodes.
double HazardPerEpisodeStep(const ViewFailureRecord& record);

// Start weights per view, summing to 1: a `share` in proportion to each
// view's `measure` (FullRolloutFailure, FailureHazard or
// HazardPerEpisodeStep; an unknown view counts as the known views' mean),
// the rest uniform. Uniform when no view is known to fail.
std::vector<double> HardViewWeights(
    const std::vector<ViewFailureRecord>& records,
    const std::vector<int>& num_frames, double share,
    HardViewMeasure measure = HardViewMeasure::kFullRollout);

class HardViewSampler {
 public:
  // `share`, `half_life_samples`, `measure`: AsiOptions' hard_view_share,
  // hard_view_half_life_samples and hard_view_measure.
  HardViewSampler(const TrackingReference& reference, double share,
                  double half_life_samples,
                  HardViewMeasure measure = HardViewMeasure::kFullRollout);

  // Ages the records by a batch of `batch_samples` and adds the episodes
  // that ended in it.
  void Record(const std::vector<FinishedEpisode>& finished,
              int64_t batch_samples);
  std::vector<double> Weights() const;
  // A brief report: the mean failure chance over the views with episodes,
  // then the `count` views with episodes and the largest start weights,
  // each with its chance, mean episode length (steps) and weight ("...;
  // hardest: kick view 2 0.93 (12 steps, w 0.061), ...").
  std::string Report(int count) const;

 private:
  std::vector<std::string> view_names_;
  std::vector<int> num_frames_;
  double share_;
  double half_life_samples_;
  HardViewMeasure measure_;
  std::vector<ViewFailureRecord> records_;
};

}  // namespace m2d

#endif  // MIMIC2D_RL_HARD_VIEWS_H_
