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
    if (error.worst_keypoint < 0 || distance_px > error.max_px) {
      error.max_px = distance_px;
      error.worst_keypoint = j;
    }
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
  // Like the pose term, a frame without reference keypoints costs nothing.
  if (weights.worst_weight > 0.0)
    terms.worst = std::exp(-weights.worst_alpha_per_px * pose_error.max_px);
  terms.total =
      weights.pose_weight * terms.pose + weights.energy_weight * terms.energy +
      weights.object_weight * terms.object + weights.worst_weight * terms.worst;
  return terms;
}

ReprojectionError CombineViewErrors(const ReprojectionError* errors,
                                    int num_views) {
  if (num_views == 1) return errors[0];
  ReprojectionError combined;
  int measured_views = 0;  // a view without keypoints this frame has no mean
  for (int k = 0; k < num_views; ++k) {
    if (errors[k].max_px > combined.max_px ||
        (combined.worst_keypoint < 0 && errors[k].worst_keypoint >= 0)) {
      combined.max_px = errors[k].max_px;
      combined.worst_keypoint = errors[k].worst_keypoint;
      combined.worst_view = k;
    }
    combined.num_present += errors[k].num_present;
    combined.any_behind_camera |= errors[k].any_behind_camera;
    if (errors[k].num_present == 0) continue;
    combined.weighted_sum_px += errors[k].weighted_sum_px;
    combined.mean_px += errors[k].mean_px;
    ++measured_views;
  }
  if (measured_views > 0) {
    combined.weighted_sum_px /= measured_views;
    combined.mean_px /= measured_views;
  }
  return combined;
}

bool ShouldExitEarly(const ReprojectionError& error, double max_error_px,
                     FrameErrorMeasure measure) {
  const double frame_error_px =
      measure == FrameErrorMeasure::kWorst ? error.max_px : error.mean_px;
  return error.any_behind_camera || frame_error_px > max_error_px;
}

Tracking3DError MeasureTracking3D(const BodyTarget3D& simulated,
                                  const BodyTarget3D& reference) {
  Tracking3DError error;
  for (size_t j = 0; j < reference.joint_rotations.size(); ++j) {
    const double angle = simulated.joint_rotations[j].angularDistance(
        reference.joint_rotations[j]);
    error.joint_rotation_sq_rad2 += angle * angle;
    error.joint_velocity_sq += (simulated.joint_angular_velocities_rad_s[j] -
                                reference.joint_angular_velocities_rad_s[j])
                                   .squaredNorm();
  }
  error.root_position_sq_m2 =
      (simulated.root_position_m - reference.root_position_m).squaredNorm();
  const double root_angle =
      simulated.root_orientation.angularDistance(reference.root_orientation);
  error.root_rotation_sq_rad2 = root_angle * root_angle;
  error.root_velocity_sq =
      (simulated.root_linear_velocity_m_s - reference.root_linear_velocity_m_s)
          .squaredNorm() +
      0.1 * (simulated.root_angular_velocity_rad_s -
             reference.root_angular_velocity_rad_s)
                .squaredNorm();
  const size_t num_keypoints = reference.keypoints_m.size();
  double sum_m = 0.0;
  for (size_t k = 0; k < num_keypoints; ++k) {
    const Eigen::Vector3d local =
        (simulated.keypoints_m[k] - simulated.root_position_m) -
        (reference.keypoints_m[k] - reference.root_position_m);
    error.keypoint_local_sq_m2 += local.squaredNorm();
    const double distance_m =
        (simulated.keypoints_m[k] - reference.keypoints_m[k]).norm();
    error.max_keypoint_m = std::max(error.max_keypoint_m, distance_m);
    sum_m += distance_m;
  }
  if (num_keypoints > 0) error.mean_keypoint_m = sum_m / num_keypoints;
  error.num_objects = static_cast<int>(reference.object_positions_m.size());
  for (int o = 0; o < error.num_objects; ++o) {
    error.object_sq_m2 +=
        (simulated.object_positions_m[o] - reference.object_positions_m[o])
            .squaredNorm();
  }
  return error;
}

void Body3DRewardWeights::Validate() const {
  CheckRanges(*this, "env.reward_3d");
}

RewardTerms ComputeReward3D(const Tracking3DError& error, double abs_power_w,
                            const Body3DRewardWeights& weights,
                            double energy_weight) {
  RewardTerms terms;
  terms.pose =
      weights.pose_weight *
          std::exp(-weights.pose_scale * error.joint_rotation_sq_rad2) +
      weights.velocity_weight *
          std::exp(-weights.velocity_scale * error.joint_velocity_sq) +
      weights.root_weight *
          std::exp(-weights.root_scale * (error.root_position_sq_m2 +
                                          0.1 * error.root_rotation_sq_rad2)) +
      weights.root_velocity_weight *
          std::exp(-weights.root_velocity_scale * error.root_velocity_sq) +
      weights.keypoint_weight *
          std::exp(-weights.keypoint_scale * error.keypoint_local_sq_m2);
  terms.energy = -abs_power_w;
  if (error.num_objects > 0)
    terms.object = std::exp(-weights.object_scale * error.object_sq_m2);
  terms.total = terms.pose + energy_weight * terms.energy +
                weights.object_weight * terms.object;
  return terms;
}

}  // namespace m2d
