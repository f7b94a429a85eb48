#include "env/reward.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace m2d {

ReprojectionError MeasureReprojection(const double* projected_xy_px,
                                      const bool* in_front,
                                      const Keypoint2D* reference,
                                      int num_keypoints,
                                      double behind_penalty_px) {
  ReprojectionError error;
  double sum_px = 0.0;
  for (int j = 0; j < num_keypoints; ++j) {
    const Keypoint2D& target = reference[j];
    if (!target.IsPresent()) continue;
    double distance_px;
    if (in_front[j]) {
      double dx = projected_xy_px[2 * j] - target.x_px;
      double dy = projected_xy_px[2 * j + 1] - target.y_px;
      distance_px = std::sqrt(dx * dx + dy * dy);
    } else {
      distance_px = behind_penalty_px;
      error.any_behind_camera = true;
    }
    error.weighted_sum_px += target.confidence * distance_px;
    sum_px += distance_px;
    error.max_px = std::max(error.max_px, distance_px);
    ++error.num_present;
  }
  error.mean_px = error.num_present > 0 ? sum_px / error.num_present : 0.0;
  return error;
}

void RewardWeights::Validate() const { CheckRanges(*this, "env.reward"); }

RewardTerms ComputeReward(const ReprojectionError& pose_error,
                          double abs_power_w,
                          const ReprojectionError* object_error,
                          const RewardWeights& weights) {
  RewardTerms terms;
  terms.pose =
      std::exp(-weights.pose_alpha_per_px * pose_error.weighted_sum_px);
  terms.energy = -abs_power_w;
  if (object_error != nullptr && object_error->num_present > 0) {
    terms.object =
        std::exp(-weights.object_alpha_per_px * object_error->weighted_sum_px);
  }
  terms.total = weights.pose_weight * terms.pose +
                weights.energy_weight * terms.energy +
                weights.object_weight * terms.object;
  return terms;
}

bool ShouldExitEarly(const ReprojectionError& error, double max_error_px) {
  return error.any_behind_camera || error.max_px > max_error_px;
}

}  // namespace m2d
