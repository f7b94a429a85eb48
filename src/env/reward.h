// env: the 2D tracking task — reference preparation, observations, rewards,
// early exit, initial-state buffers, and (vectorized) environments.
#ifndef MIMIC2D_ENV_REWARD_H_
#define MIMIC2D_ENV_REWARD_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "common/settings.h"
#include "motion/clip2d.h"

namespace m2d {

// Which of a frame's keypoint errors the early exit (and so evaluation's
// Succ) compares with its threshold. The paper's criterion reads "failure
// if max reprojection > 100 pixels"; we take the max over keypoints. PHC,
// whose success rule the paper's follows, fails a rollout when the mean
// over joints is off by more than its bound (0.5 m) at any frame: kMean is
// that reading in pixels, offered to evaluation for comparison
// (docs/tracking.md, "Reward and early exit").
enum class FrameErrorMeasure {
  kWorst,  // the worst keypoint (the default, in training and evaluation)
  kMean,   // the mean over the frame's present keypoints
};
inline const char* SettingName(FrameErrorMeasure measure) {
  return measure == FrameErrorMeasure::kWorst ? "worst_keypoint"
                                              : "mean_keypoint";
}
inline bool ParseSetting(const std::string& text, FrameErrorMeasure* measure) {
  return ParseSettingByName(
      text, {FrameErrorMeasure::kWorst, FrameErrorMeasure::kMean}, measure);
}
inline std::string SettingChoices(FrameErrorMeasure) {
  return "worst_keypoint, mean_keypoint";
}

// How far the character's projected keypoints are from a 2D reference frame.
struct ReprojectionError {
  double weighted_sum_px = 0.0;    // sum_j c_j |P(x_j) - x^_j| over present j
  double mean_px = 0.0;            // unweighted mean over present j
  double max_px = 0.0;             // worst present keypoint
  int worst_keypoint = -1;         // its index (-1: none present)
  int worst_view = 0;              // of K views combined, the one it is in
  int num_present = 0;             // reference keypoints that count
  bool any_behind_camera = false;  // a counted keypoint projects behind
};

// Compares projections (x, y per keypoint; `in_front` per keypoint) with
// one reference frame. Missing reference keypoints are skipped; a keypoint
// behind the camera counts as `behind_penalty_px` of error.
ReprojectionError MeasureReprojection(const double* projected_xy_px,
                                      const bool* in_front,
                                      const Keypoint2D* reference,
                                      int num_keypoints,
                                      double behind_penalty_px = 1000.0);

struct RewardWeights {
  double pose_weight = 1.0;           // w_p
  double pose_alpha_per_px = 0.004;   // alpha, on the weighted sum (1/px)
  double energy_weight = 1e-4;        // w_e, per watt of |qdot . tau|
  double object_weight = 0.0;         // weight of the object 2D term
  double object_alpha_per_px = 0.02;  // alpha of the object term (1/px)
  // The worst keypoint's own term. The early exit (and so Succ) is decided by
  // the worst keypoint, but the tracking term sees it only as one of 17 in a
  // sum, so a foot drifting while the body tracks costs little until the
  // episode ends (docs/generation.md 4b, "A term for the worst keypoint").
  double worst_weight = 0.0;         // w_w (0: no such term)
  double worst_alpha_per_px = 0.02;  // alpha_w, on the worst keypoint (1/px)

  // Every setting (common/settings.h); a training config's `env.reward`.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("pose_weight", self.pose_weight, Range::AtLeast(0),
      "w_p, weight of the 2D reprojection term exp(-alpha * error)");
    v("pose_alpha_per_px", self.pose_alpha_per_px, Range::Above(0),
      "alpha (1/px) on the confidence-weighted keypoint error sum");
    v("energy_weight", self.energy_weight, Range::AtLeast(0),
      "w_e, per watt of mechanical power sum_j abs(qdot_j tau_j) (a "
      "penalty)");
    v("object_weight", self.object_weight, Range::AtLeast(0),
      "weight of the object's 2D term (0: no object)");
    v("object_alpha_per_px", self.object_alpha_per_px, Range::Above(0),
      "alpha (1/px) of the object term");
    v("worst_weight", self.worst_weight, Range::AtLeast(0),
      "w_w, weight of exp(-alpha_w * the worst keypoint's error), the "
      "keypoint the early exit compares (0: no such term)");
    v("worst_alpha_per_px", self.worst_alpha_per_px, Range::Above(0),
      "alpha_w (1/px) on the worst keypoint's error");
  }
  void Validate() const;  // throws ConfigError
};

struct RewardTerms {
  // The tracking term: exp(-alpha * weighted_sum_px), in (0, 1]; for 3D
  // tracking the weighted sum of its terms.
  double pose = 0.0;
  double energy = 0.0;  // -sum_j |qdot_j tau_j| (W), <= 0
  double object = 0.0;  // exp(-alpha_o * object error), 0 if untracked
  double worst = 0.0;   // exp(-alpha_w * max_j |P(x_j) - x^_j|); 0 if w_w = 0
  double total = 0.0;   // w_p pose + w_e energy + w_o object + w_w worst
};

// r = w_p exp(-alpha sum_j c_j |P(x_j) - x^_j|) + w_e r_e (+ w_o r_o)
// (+ w_w exp(-alpha_w max_j |P(x_j) - x^_j|)), with r_e = -sum_j |qdot_j
// tau_j|. `object_error` may be null (no object).
RewardTerms ComputeReward(const ReprojectionError& pose_error,
                          double abs_power_w,
                          const ReprojectionError* object_error,
                          const RewardWeights& weights);

// One frame's errors in K views of the same motion, as one: the worst
// keypoint of any view (and which view); the sums and means averaged over the
// views that had keypoints; the present counts summed; behind the camera in
// any. K = 1 returns the error itself.
ReprojectionError CombineViewErrors(const ReprojectionError* errors,
                                    int num_views);

// Reprojection early exit: the episode ends when the frame's error by
// `measure` (the worst keypoint's, or the mean) is more than `max_error_px`,
// or any keypoint projects behind the camera.
bool ShouldExitEarly(const ReprojectionError& error, double max_error_px,
                     FrameErrorMeasure measure = FrameErrorMeasure::kWorst);

// ---- 3D tracking (the 3D-supervised and two-stage baselines) ----

// The character's state at one frame, as 3D tracking compares it: root
// pose and velocity (MuJoCo's free joint: linear velocity in the world,
// angular in the root's frame), each moving joint's rotation and angular
// velocity, keypoints.
//
// Joints are compared as rotations, not hinge angles: a ball joint's three
// hinges reach most rotations by two Euler solutions, and a reference
// converted frame by frame switches between them where nothing moves
// (kick, dance_a, spin), while a simulated episode keeps the solution it
// started in. Rotations and angular velocities do not depend on the solution.
struct BodyTarget3D {
  Eigen::Vector3d root_position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond root_orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d root_linear_velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d root_angular_velocity_rad_s = Eigen::Vector3d::Zero();
  // Per moving (ball or revolute) joint, in skeleton order: its body's
  // rotation relative to the parent body, and its angular velocity relative
  // to the parent's, in the parent's frame (rad/s).
  std::vector<Eigen::Quaterniond> joint_rotations;
  std::vector<Eigen::Vector3d> joint_angular_velocities_rad_s;
  std::vector<Eigen::Vector3d> keypoints_m;
  // The scene's tracked free objects (a ball), in object point order
  // (world); empty without objects.
  std::vector<Eigen::Vector3d> object_positions_m;
};

// How far a simulated state is from its 3D reference frame.
struct Tracking3DError {
  double joint_rotation_sq_rad2 = 0.0;  // sum_j angle(R_j, R^_j)^2
  double joint_velocity_sq = 0.0;       // sum_j |w_j - w^_j|^2 ((rad/s)^2)
  double root_position_sq_m2 = 0.0;     // |p - p^|^2 (world)
  double root_rotation_sq_rad2 = 0.0;   // angle(R, R^)^2
  double root_velocity_sq = 0.0;        // |v - v^|^2 + 0.1 |w - w^|^2
  double keypoint_local_sq_m2 = 0.0;    // sum_k |(x_k - p) - (x^_k - p^)|^2
  double max_keypoint_m = 0.0;          // worst |x_k - x^_k| (world)
  double mean_keypoint_m = 0.0;         // mean |x_k - x^_k| (world)
  int num_objects = 0;                  // objects compared (0: none)
  double object_sq_m2 = 0.0;            // sum_o |b_o - b^_o|^2 (world)
};

// Compares two states of the same character (sizes must agree).
Tracking3DError MeasureTracking3D(const BodyTarget3D& simulated,
                                  const BodyTarget3D& reference);

// DeepMimic-style terms, with MimicKit's weights and scales as defaults
// (../shared/notes/reference-settings.md).
struct Body3DRewardWeights {
  double pose_weight = 0.5;             // on exp(-pose_scale * rotation_sq)
  double pose_scale = 2.0;              // 1/rad^2
  double velocity_weight = 0.1;         // on exp(-velocity_scale * vel_sq)
  double velocity_scale = 0.1;          // 1/(rad/s)^2
  double root_weight = 0.15;            // on exp(-root_scale * (pos + 0.1 rot))
  double root_scale = 5.0;              // 1/m^2
  double root_velocity_weight = 0.1;    // on exp(-root_velocity_scale * ...)
  double root_velocity_scale = 1.0;     // 1/(m/s)^2
  double keypoint_weight = 0.15;        // on exp(-keypoint_scale * sum)
  double keypoint_scale = 10.0;         // 1/m^2
  double early_exit_max_error_m = 0.5;  // worst keypoint farther ends the
                                        // episode (0: never)
  // The objects' term (a ball; 0: none), on the world positions: the
  // two-stage baseline's ball, whose 3D it tracks as it tracks the body's.
  double object_weight = 0.0;  // on exp(-object_scale * object_sq)
  double object_scale = 5.0;   // 1/m^2 (the root's)

  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("pose_weight", self.pose_weight, Range::AtLeast(0),
      "weight of exp(-pose_scale * sum of squared joint-rotation angles "
      "between the character and its reference)");
    v("pose_scale", self.pose_scale, Range::AtLeast(0), "1/rad^2");
    v("velocity_weight", self.velocity_weight, Range::AtLeast(0),
      "weight of exp(-velocity_scale * sum of squared joint angular-"
      "velocity errors)");
    v("velocity_scale", self.velocity_scale, Range::AtLeast(0), "1/(rad/s)^2");
    v("root_weight", self.root_weight, Range::AtLeast(0),
      "weight of exp(-root_scale * (root position error^2 + 0.1 root "
      "rotation error^2))");
    v("root_scale", self.root_scale, Range::AtLeast(0), "1/m^2");
    v("root_velocity_weight", self.root_velocity_weight, Range::AtLeast(0),
      "weight of exp(-root_velocity_scale * (linear^2 + 0.1 angular^2 "
      "velocity error))");
    v("root_velocity_scale", self.root_velocity_scale, Range::AtLeast(0),
      "1/(m/s)^2");
    v("keypoint_weight", self.keypoint_weight, Range::AtLeast(0),
      "weight of exp(-keypoint_scale * sum of squared root-relative "
      "keypoint errors)");
    v("keypoint_scale", self.keypoint_scale, Range::AtLeast(0), "1/m^2");
    v("early_exit_max_error_m", self.early_exit_max_error_m, Range::AtLeast(0),
      "an episode ends when a keypoint is farther than this from its 3D "
      "reference (m; 0: never)");
    v("object_weight", self.object_weight, Range::AtLeast(0),
      "weight of exp(-object_scale * sum of squared world-position errors "
      "of the tracked objects, a ball; 0: objects not rewarded)");
    v("object_scale", self.object_scale, Range::AtLeast(0), "1/m^2");
  }
  void Validate() const;  // throws ConfigError
};

// r = sum of the weighted body terms above (RewardTerms::pose) + w_e r_e
// (the energy term of the 2D reward, so that the tracking term is the only
// difference) + w_o exp(-object_scale object_sq) when objects are compared
// (RewardTerms::object unweighted, as in the 2D reward).
RewardTerms ComputeReward3D(const Tracking3DError& error, double abs_power_w,
                            const Body3DRewardWeights& weights,
                            double energy_weight);

}  // namespace m2d

#endif  // MIMIC2D_ENV_REWARD_H_
