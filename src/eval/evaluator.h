// eval: rolls a policy out on every view of every bundle and reports the
// paper's metrics per (bundle, view).
#ifndef MIMIC2D_EVAL_EVALUATOR_H_
#define MIMIC2D_EVAL_EVALUATOR_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "env/policy.h"
#include "env/reference.h"
#include "env/tracking_env.h"

namespace m2d {

struct EvalOptions {
  int episodes_per_view = 10;           // start frames spread over the clip
  double episode_s = 10.0;              // episode length (clip end cuts it)
  double success_threshold_px = 100.0;  // a frame whose error (by
                                        // success_measure) is off by more
                                        // fails the rollout
  // Which frame error the threshold bounds: the worst keypoint's (the
  // paper's "max reprojection" as we read it; every table of docs/) or the
  // mean over keypoints (PHC's rule in pixels), for comparison.
  FrameErrorMeasure success_measure = FrameErrorMeasure::kWorst;
  // K: views observed at once (zero-shot multi-view tracking, phi averaged
  // over them). K > 1 evaluates, for every bundle with at least K views and
  // each of its views in turn, that view with the K - 1 next ones (in the
  // bundle's order, wrapping); it needs the true cameras (one world).
  int num_views = 1;
  // The paper's robustness tests (its dribble: periodic 300 N pushes;
  // "w/ Rnd.", the ball placed at random in a 1 x 1 m area). Pushes on the
  // root and objects moved within a square of object_start_square_m on the
  // floor (0: none; needs objects), both as the environment applies them in
  // training (env/tracking_env.h). Push directions and offsets are drawn from
  // perturbation_seed: an evaluation repeats exactly.
  PushOptions pushes;
  double object_start_square_m = 0.0;
  uint64_t perturbation_seed = 1;
  // The episodes' camera (env/tracking_env.h); unset: the policy's training
  // setting (its config's env.camera).
  std::optional<EpisodeCamera> camera;
  // Keep every rollout's per-frame errors (EvalRollout::trace; eval
  // --frames): where and on which keypoint a rollout starts to fail.
  bool record_frames = false;
  void Validate() const;  // throws ConfigError
};

// The environment a rollout is judged in: the policy's training options
// with the early exit exactly at the success rule (threshold and measure),
// episodes of options.episode_s, the perturbations options asks for (none by
// default) and a 3D baseline's own 3D exit off. Training's exit may be
// stricter or looser than the rule (env.early_exit_max_error_px); every
// policy is judged by the same rule whatever it trained with. Pure.
TrackingEnvOptions JudgedEnvOptions(const TrackingEnvOptions& trained,
                                    const EvalOptions& options);

// What ended a rollout.
enum class RolloutEnd {
  kEarlyExit,  // a frame over the success threshold (or behind a camera)
  kDiverged,   // the simulation became unstable
  kClipEnd,    // the reference's last frame
  kTimeLimit,  // episode_s
};
const char* RolloutEndName(RolloutEnd end);  // "early_exit", ...

// One simulated frame of a rollout, as the success rule judged it.
struct EvalFrame {
  int frame = 0;              // the reference frame the step reached
  int keypoints_present = 0;  // reference keypoints compared (all K views)
  double mean_px = 0.0;       // mean keypoint error (K views: their mean)
  double worst_px = 0.0;      // the worst keypoint's error
  int worst_keypoint = -1;    // its index in the character's layout (-1:
                              // none present, or the step diverged)
  int worst_view = 0;         // of the K views, the one it is in
  double pa_mm = -1.0;        // this frame's PA-MPJPE (-1: no truth)
};

// One evaluation rollout (to find which start fails).
struct EvalRollout {
  int start_frame = 0;
  int frames = 0;  // until the first failing frame or the end
  bool succeeded = false;
  double e2d_px = 0.0;
  RolloutEnd end = RolloutEnd::kClipEnd;
  int last_worst_keypoint = -1;  // the last step's worst keypoint (the one
                                 // that failed it, for an early exit)
  std::vector<EvalFrame> trace;  // per step, with record_frames only
};

struct EvalRow {
  std::string bundle;
  std::string view;  // with K views: their names joined by '+'
  int episodes = 0;
  // Fraction of successful rollouts: no frame over the threshold (in any of
  // the K views), and at least half of the frames had reference keypoints
  // to judge them by. E2D: over the K views, their mean.
  double succ = 0.0;
  // Mean per-frame mean 2D error (until failure) over the frames that had
  // reference keypoints; -1 when no rollout measured any (e.g. every start
  // diverged at once). E3D and Jitter likewise (-1: nothing simulated).
  double e2d_px = 0.0;
  double eo2d_px = -1.0;  // objects' 2D error; -1 without objects
  // Against the 3D truth (-1 without it). Global error only when the
  // cameras are the true ones (the worlds agree; else -1); root-relative
  // after the best rotation about z when they are estimated (an estimate's
  // heading is arbitrary); Procrustes-aligned (PA-MPJPE) always.
  double e3d_mm = -1.0;
  double e3d_root_mm = -1.0;
  double e3d_pa_mm = -1.0;
  double jitter = 0.0;                // 10^3 m/s^3
  double mean_frames = 0.0;           // frames rolled out per episode
  std::vector<EvalRollout> rollouts;  // empty in aggregates
};

// Episodes start from each frame's best-scoring initial state, use the
// policy's deterministic action, and end at the first failing frame, the
// clip end, or episode_s. `truth` holds, per bundle of the reference, its 3D
// truth for measurement only (nullopt or empty: no E3D): it is given here,
// apart from the reference, so that a policy that never saw it can still be
// measured against it.
std::vector<EvalRow> EvaluatePolicy(
    Policy& policy, std::shared_ptr<const Character> character,
    std::shared_ptr<const TrackingReference> reference,
    std::shared_ptr<const InitialStates> initial_states,
    const TrackingEnvOptions& env_options, const EvalOptions& options,
    const std::vector<std::optional<GroundTruth3D>>& truth = {});

// Mean of the rows, weighted by episodes ("all" row).
EvalRow AggregateRows(const std::vector<EvalRow>& rows);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_EVALUATOR_H_
