// env: the 2D tracking environment. An episode draws a (bundle, view) pair
// and a start frame, starts from that frame's initial-state buffer, and
// rewards the character for projecting, through the view's camera, onto the
// 2D reference. The camera is never observed. For zero-shot multi-view
// tracking an environment observes K views of one bundle at once (one 2D
// block each; the policy averages phi over them).
#ifndef MIMIC2D_ENV_TRACKING_ENV_H_
#define MIMIC2D_ENV_TRACKING_ENV_H_

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "camera/pinhole.h"
#include "common/settings.h"
#include "env/observation.h"
#include "env/reference.h"
#include "env/reward.h"
#include "sim/simulation.h"

namespace m2d {

// What an episode's reward follows.
enum class TrackingTarget {
  kImage2D,  // the paper's: the 2D reference through the view's camera
  kBody3D,   // the baselines': a 3D reference, the motion the initial
             // states were filled from (the 3D truth for 3D-GT, a view's
             // fitted poses for the two-stage Sfv*), observed as 3D
             // keypoints relative to the character instead of 2D
};
inline const char* SettingName(TrackingTarget target) {
  return target == TrackingTarget::kImage2D ? "image_2d" : "body_3d";
}
inline bool ParseSetting(const std::string& text, TrackingTarget* target) {
  return ParseSettingByName(
      text, {TrackingTarget::kImage2D, TrackingTarget::kBody3D}, target);
}
inline std::string SettingChoices(TrackingTarget) {
  return "image_2d, body_3d";
}

// Where an episode's camera is at each frame.
enum class EpisodeCamera {
  kRecorded,  // the view's camera of the frame, as recorded (or fitted)
  // The view's camera of the frame moved horizontally by the simulated
  // root's offset from the reference motion's root at the frame (the
  // motion the initial states come from: the fit's poses with
  // initial_states estimate): a camera that dollies with the character,
  // for views filmed by one that dollied with the subject (`clip
  // from-motion --follow`, a following video), whose 2D holds the body
  // but not its path over the ground. The rollouts of `generate --policy`
  // see the character so.
  kFollowsCharacter,
  // The episode's start frame's kFollowsCharacter camera, then moved only
  // with the simulated root (horizontally): the camera of `generate
  // --policy`'s rollouts, which know one fitted camera, the start's, and
  // dolly it with the character; the per-frame fitted cameras' turns and
  // tilts are not followed.
  kDolliesFromStart,
};
inline const char* SettingName(EpisodeCamera camera) {
  switch (camera) {
    case EpisodeCamera::kRecorded:
      return "recorded";
    case EpisodeCamera::kFollowsCharacter:
      return "follows_character";
    case EpisodeCamera::kDolliesFromStart:
      return "dollies_from_start";
  }
  return "?";
}
inline bool ParseSetting(const std::string& text, EpisodeCamera* camera) {
  return ParseSettingByName(
      text,
      {EpisodeCamera::kRecorded, EpisodeCamera::kFollowsCharacter,
       EpisodeCamera::kDolliesFromStart},
      camera);
}
inline std::string SettingChoices(EpisodeCamera) {
  return "recorded, follows_character, dollies_from_start";
}

// `recorded` moved horizontally by the offset of `simulated_root_m` from
// `reference_root_m` (world, m): EpisodeCamera::kFollowsCharacter's camera.
PinholeCamera CameraFollowingCharacter(const PinholeCamera& recorded,
                                       const Eigen::Vector3d& reference_root_m,
                                       const Eigen::Vector3d& simulated_root_m);

// Synthetic detector noise on the 2D reference of an episode.
struct ReferenceNoise {
  double pixel_sigma_px = 0.0;    // Gaussian, on x and y
  double drop_probability = 0.0;  // a keypoint missed (confidence 0)
  bool enabled() const { return pixel_sigma_px > 0 || drop_probability > 0; }
};

// Pushes on the root body: a horizontal force of force_n, in a direction
// drawn per push, that starts every every_s into an episode (not at its
// start) and lasts duration_s. The paper's robustness test (`eval --push`:
// periodic 300 N) and, in training, practice for it. 0 N: no pushes.
struct PushOptions {
  double force_n = 0.0;
  double every_s = 2.0;
  double duration_s = 0.2;

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("force_n", self.force_n, Range::AtLeast(0),
      "horizontal force on the root body (N), in a direction drawn per "
      "push; 0: no pushes");
    v("every_s", self.every_s, Range::Above(0),
      "a push starts every this long into an episode (s)");
    v("duration_s", self.duration_s, Range::Above(0),
      "each push lasts this long (s; at most every_s)");
  }
  void Validate() const;  // throws ConfigError
};

// Which push acts during control step `step` of an episode (steps at
// `control_hz`): k >= 1 for the k-th, from k every_s for duration_s; 0
// between pushes and without them.
int PushAtStep(int step, double control_hz, const PushOptions& pushes);

struct TrackingEnvOptions {
  SimulationOptions simulation;
  int num_future_frames = 5;               // L reference frames observed ahead
  double max_episode_s = 10.0;             // episodes are truncated after this
  bool early_exit = true;                  // reprojection early exit on/off
  double early_exit_max_error_px = 100.0;  // frame error that ends it (px)
  // Which error early_exit_max_error_px bounds: training keeps the worst
  // keypoint; evaluation may judge by the mean (EvalOptions).
  FrameErrorMeasure early_exit_measure = FrameErrorMeasure::kWorst;
  RewardWeights reward;
  TrackingTarget target = TrackingTarget::kImage2D;
  Body3DRewardWeights reward_3d;  // with target body_3d (energy: reward's)
  // Asymmetric actor-critic: observations carry the critic-only block
  // (env/observation.h, WriteCriticOnlyInputs; the 3D reference the initial
  // states come from, and the camera), which the policy never reads.
  bool critic_observes_3d = false;
  // Noisy S.I.: sigma (rad) added once to the joint angles of the
  // initial-state buffers when they are filled; ASI replaces them with
  // visited states. Read by whoever fills the buffers (the Trainer passes it
  // to InitialStates), not by the environment; 0 disables.
  double initial_state_noise_rad = 0.0;
  // Detector noise on the 2D reference of training episodes, drawn afresh
  // for each episode (clean synthetic 2D made to look detected: pixel
  // noise (px) and misses). Read by the trainer, which sets it on its
  // collection environments (VecEnv::SetReferenceNoise); evaluation and
  // replays track the reference as given. 0 disables.
  double training_reference_noise_px = 0.0;
  double training_reference_drop = 0.0;
  // The share of episodes (Reset) that start at their clip's first frame
  // rather than at a uniformly drawn one. A rollout judged from the first
  // frame (the tables' protocol), or a clip whose decisive moment comes
  // early (a kick at frame 11 of 121), is otherwise practised by 1/T of the
  // starts. 0: uniform, drawing nothing extra (runs stay bit-identical).
  double first_frame_start_share = 0.0;
  PushOptions pushes;  // none by default
  EpisodeCamera camera = EpisodeCamera::kRecorded;
  // Moved objects: every episode's tracked objects (a ball) start offset on
  // the floor, uniformly in a square of this side (m) about where the start
  // state has them, drawn from the environment's seed. The paper's "w/ Rnd."
  // test (`eval --object-start-square 1`) and, in training, practice for it.
  // 0: where the start state has them.
  double object_start_square_m = 0.0;

  // Every setting (common/settings.h); a training config's `env` section
  // (the simulation's fields spliced in, the reward as `env.reward`).
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    decltype(self.simulation)::VisitFields(self.simulation, v);
    v("num_future_frames", self.num_future_frames, Range::Closed(1, 1000),
      "L: future reference frames in the observation");
    v("max_episode_s", self.max_episode_s, Range::Above(0),
      "episodes are truncated after this (s)");
    v("early_exit", self.early_exit, Range::Any(),
      "end an episode when a frame's error (early_exit_measure) is more "
      "than early_exit_max_error_px (the paper's reprojection early exit)");
    v("early_exit_max_error_px", self.early_exit_max_error_px, Range::Above(0),
      "the early exit's threshold (px)");
    v("early_exit_measure", self.early_exit_measure, Range::Any(),
      "which frame error the threshold bounds: worst_keypoint (the paper's "
      "'max reprojection', as read here) or mean_keypoint (PHC's success "
      "rule in pixels)");
    v("initial_state_noise_rad", self.initial_state_noise_rad,
      Range::AtLeast(0),
      "Noisy S.I.: sigma (rad) added once to the joint angles of the "
      "initial-state buffers when they are filled");
    v("training_reference_noise_px", self.training_reference_noise_px,
      Range::AtLeast(0),
      "training episodes' 2D reference: Gaussian detector noise drawn "
      "afresh per episode (px; evaluation sees the reference as given)");
    v("training_reference_drop", self.training_reference_drop,
      Range{0, 1, /*min_open=*/false, /*max_open=*/true},
      "training episodes' 2D reference: the chance a keypoint is missed "
      "(confidence 0), drawn afresh per episode");
    v("first_frame_start_share", self.first_frame_start_share,
      Range::Closed(0, 1),
      "share of training episodes that start at their clip's first frame "
      "instead of a uniformly drawn one; 0: uniform");
    v.Nested("reward", self.reward);
    v.Nested("pushes", self.pushes);
    v("camera", self.camera, Range::Any(),
      "recorded (each frame's camera as the view has it: true or fitted) "
      "or follows_character (that camera moved horizontally by the "
      "simulated root's offset from the initial states' motion's root at "
      "the frame: a camera dollying with the character, for following "
      "views, whose 2D holds no path over the ground) or dollies_from_start "
      "(the start frame's follows_character camera, then moved with the "
      "simulated root alone: generate --policy's camera); the last two "
      "need initial_states truth or estimate");
    v("object_start_square_m", self.object_start_square_m, Range::AtLeast(0),
      "each episode's tracked objects (the ball) start moved on the floor "
      "uniformly within a square of this side (m) about their start; 0: "
      "not moved");
    v("target", self.target, Range::Any(),
      "image_2d (the paper's 2D reprojection reward) or body_3d (the "
      "3D-tracking baselines: a DeepMimic-style reward on the motion the "
      "initial states come from, 3D keypoints observed instead of 2D)");
    v.Nested("reward_3d", self.reward_3d);
    v("critic_observes_3d", self.critic_observes_3d, Range::Any(),
      "asymmetric actor-critic: the critic (only) also sees the 3D "
      "reference the initial states come from (the fit's poses with "
      "initial_states estimate) and the episode's camera; the policy's "
      "inputs are unchanged");
  }

  ReferenceNoise training_reference_noise() const {
    return {training_reference_noise_px, training_reference_drop};
  }
  int max_episode_steps() const {
    return static_cast<int>(max_episode_s * simulation.control_hz + 0.5);
  }
  void Validate() const;  // throws ConfigError
};

// What one Step() did.
struct StepOutcome {
  float reward = 0.0f;
  bool terminated = false;  // early exit or divergence: no bootstrap
  bool truncated = false;   // time limit or end of reference
  // Truncated because the reference's last frame was reached: the task is
  // over (nothing follows to track), unlike a time limit's cut.
  bool reference_ended = false;
  bool diverged = false;
  ReprojectionError error;  // of the new frame
  RewardTerms terms;
};

// Running statistics of the current episode (for logs and evaluation).
struct EpisodeStats {
  int view_index = 0;  // into TrackingReference::views()
  int start_frame = 0;
  int steps = 0;
  // Steps whose reference frame had at least one keypoint to compare with
  // (a frame with none cannot be judged: it is neither error nor success).
  int measured_steps = 0;
  double total_reward = 0.0;
  double sum_mean_error_px = 0.0;  // sum over measured steps of the mean
  double max_error_px = 0.0;       // worst keypoint over the episode
  bool failed = false;             // ended by early exit or divergence

  double mean_error_px() const {
    return measured_steps ? sum_mean_error_px / measured_steps : 0.0;
  }
};

// Most views one environment observes at once (zero-shot multi-view).
inline constexpr int kMaxObservedViews = 16;

class TrackingEnv {
 public:
  // `num_observed_views` (K): 2D blocks per observation; K > 1 episodes
  // start with ResetToViews.
  TrackingEnv(std::shared_ptr<const Character> character,
              std::shared_ptr<const TrackingReference> reference,
              std::shared_ptr<const InitialStates> initial_states,
              const TrackingEnvOptions& options, uint64_t seed,
              int num_observed_views = 1);

  const ObservationLayout& layout() const { return layout_; }
  int num_observed_views() const { return num_observed_views_; }
  int observation_size() const {
    return layout_.view_offset() + num_observed_views_ * layout_.view_size();
  }
  int action_size() const { return simulation_.character().num_actions(); }

  // Starts an episode at a random view and frame; writes its observation.
  void Reset(float* observation);
  // Starts an episode at a given view and frame with a given state (K = 1).
  void ResetTo(int view_index, int frame, const SimState& state,
               float* observation);
  // Starts an episode observing K views (indices into
  // TrackingReference::views(), all of one bundle: the same motion in one
  // world). The first is the episode's view; a frame fails when any view's
  // worst keypoint is off, and the error and reward are the views' means.
  void ResetToViews(const std::vector<int>& view_indices, int frame,
                    const SimState& state, float* observation);
  // Tracks `reference` from now on (the next ResetTo picks a view of it),
  // keeping the simulation: for a reference that arrives piecewise
  // (env/reference_stream.h). Its points per frame and objects must be the
  // current one's (the observation layout); ConfigError otherwise.
  void Rebase(std::shared_ptr<const TrackingReference> reference);
  // From the next episode on, every episode observes and is rewarded
  // against its views' 2D through `noise`, drawn afresh (from this
  // environment's seed) for each episode and frame; the shared reference
  // stays as given. A disabled noise restores it from the next episode.
  void SetReferenceNoise(const ReferenceNoise& noise);
  // Advances one control period. Writes the next observation unless the
  // episode ended (the caller resets).
  StepOutcome Step(const float* action, float* observation);

  const EpisodeStats& episode() const { return episode_; }
  int frame() const { return frame_; }
  const TrackedView& view() const { return *view_; }
  const Simulation& simulation() const { return simulation_; }
  Simulation& mutable_simulation() { return simulation_; }
  // The simulated keypoints projected by the episode's camera at the
  // current frame (x, y per point; valid after Reset/Step); with K views,
  // the other views' follow in order.
  const std::vector<double>& projected_px() const { return projected_xy_; }
  // The camera the k-th observed view projects with at the current frame
  // (options' `camera`; valid after Reset/Step).
  const PinholeCamera& camera(int k = 0) const { return cameras_[k]; }
  // Per point: whether it is in front of the episode's camera (then the
  // other views').
  const bool* in_front() const { return in_front_.get(); }
  // Current observation written again (e.g. after the trainer edits state).
  void WriteObservation(float* observation);

 private:
  // Restores `state` as an episode's start, the objects moved when
  // object_start_square_m asks for it (its copy: the buffers keep theirs).
  void RestoreStart(const SimState& state);
  void BeginEpisode(int frame);
  // With reference noise: the episode's noisy views hold frames up to
  // `last_frame` (drawn the first time an episode reaches them).
  void CorruptReferenceUpTo(int last_frame);
  // Each observed view's camera at the current frame (cameras_).
  void PlaceCameras();
  void ProjectCurrentPoints();
  // A horizontal force of `force_n` at `heading_rad` on the root body
  // (world frame; 0 N clears it). MuJoCo keeps xfrc_applied until changed.
  void SetRootPush(double force_n, double heading_rad);
  void ReadBodyKinematics();  // and the objects' (ReadObjectKinematics)
  void ReadObjectKinematics();
  // With critic_observes_3d: the critic-only block of the current frame.
  void WriteCriticOnlyBlock(float* observation) const;
  // The episode's 3D reference (the initial states' motion) at `frame`,
  // held at its last frame beyond it: target body_3d's reference, and the
  // critic-only block's.
  const BodyTarget3D& ReferenceBody(int frame) const;

  std::shared_ptr<const TrackingReference> reference_;
  std::shared_ptr<const InitialStates> initial_states_;
  TrackingEnvOptions options_;
  int push_ = 0;          // the push acting (PushAtStep), 0: none
  SimState moved_start_;  // RestoreStart's copy, reused
  Simulation simulation_;
  ObservationLayout layout_;
  std::mt19937_64 rng_;

  const int num_observed_views_;
  // The episode's view first, then the other observed views.
  std::vector<const TrackedView*> observed_views_;
  const TrackedView* view_ = nullptr;  // observed_views_[0]
  int frame_ = 0;
  EpisodeStats episode_;

  // Reference noise: per observed view, the reference as given and the
  // episode's corrupted copy of it (observed_views_ then points here),
  // filled frame by frame up to corrupted_until_frame_.
  ReferenceNoise reference_noise_;
  bool episode_corrupted_ = false;  // the episode observes noisy_views_
  std::vector<const TrackedView*> clean_views_;
  std::vector<TrackedView> noisy_views_;
  int corrupted_until_frame_ = -1;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  std::uniform_real_distribution<double> unit_uniform_{0.0, 1.0};

  // Each observed view's camera at the current frame (PlaceCameras).
  std::vector<PinholeCamera> cameras_;
  // Scratch buffers, sized once (per observed view where projected).
  BodyKinematics bodies_;
  std::vector<double> keypoints_xyz_;
  std::vector<double> projected_xy_;
  std::unique_ptr<bool[]> in_front_;
  std::vector<Keypoint2D> projected_points_;
  std::vector<Eigen::Vector3d> object_positions_, object_velocities_;
  BodyTarget3D simulated_body_;                    // target body_3d
  std::vector<Eigen::Vector3d> current_points_m_;  // target body_3d keypoints
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_TRACKING_ENV_H_
