// env: the 2D tracking task — reference preparation, observations, rewards,
// early exit, initial-state buffers, and (vectorized) environments.
#ifndef MIMIC2D_ENV_REWARD_H_
#define MIMIC2D_ENV_REWARD_H_

#include "common/settings.h"
#include "motion/clip2d.h"

namespace m2d {

// How far the character's projected keypoints are from a 2D reference frame.
struct ReprojectionError {
  double weighted_sum_px = 0.0;    // sum_j c_j |P(x_j) - x^_j| over present j
  double mean_px = 0.0;            // unweighted mean over present j
  double max_px = 0.0;             // worst present keypoint
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
  }
  void Validate() const;  // throws ConfigError
};

struct RewardTerms {
  double pose = 0.0;    // exp(-alpha * weighted_sum_px), in (0, 1]
  double energy = 0.0;  // -sum_j |qdot_j tau_j| (W), <= 0
  double object = 0.0;  // exp(-alpha_o * object error), 0 if untracked
  double total = 0.0;   // w_p pose + w_e energy + w_o object
};

// r = w_p exp(-alpha sum_j c_j |P(x_j) - x^_j|) + w_e r_e (+ w_o r_o), with
// r_e = -sum_j |qdot_j tau_j|. `object_error` may be null (no object).
RewardTerms ComputeReward(const ReprojectionError& pose_error,
                          double abs_power_w,
                          const ReprojectionError* object_error,
                          const RewardWeights& weights);

// Reprojection early exit: the episode ends when the worst keypoint is more
// than `max_error_px` off, or any keypoint projects behind the camera.
bool ShouldExitEarly(const ReprojectionError& error, double max_error_px);

}  // namespace m2d

#endif  // MIMIC2D_ENV_REWARD_H_
