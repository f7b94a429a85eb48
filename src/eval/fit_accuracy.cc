#include "eval/fit_accuracy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/error.h"
#include "eval/metrics.h"
#include "fit/camera_model.h"
#include "motion/motion3d.h"
#include "sim/character.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

constexpr char kSource[] = "fit accuracy";

double Degrees(double radians) { return radians * 180.0 / M_PI; }

// |a - b| wrapped to [0, pi].
double AngleGapRad(double a, double b) {
  return std::abs(std::remainder(a - b, 2.0 * M_PI));
}

void CheckCameraCount(size_t count, int num_frames, const char* what) {
  if (count != 1 && count != static_cast<size_t>(num_frames)) {
    throw InputError(
        kSource, std::string(what) + " has " + std::to_string(count) +
                     " cameras; expected 1 or " + std::to_string(num_frames));
  }
}

// PA-MPJPE (m) of the true poses clamped to the character's hinge ranges
// against the true keypoints; 0 without true poses.
double ReachableFloorM(const GroundTruth3D& truth, const Character& character) {
  if (truth.poses.size() != truth.keypoints_m.size() ||
      truth.skeleton_name != character.skeleton().name) {
    return 0.0;
  }
  std::vector<double> qpos(character.model()->nq, 0.0);
  KeypointFrames clamped;
  for (const Pose3D& pose : truth.poses) {
    PoseToQpos(character, pose, qpos.data());
    for (const ActuatedHinge& hinge : character.hinges()) {
      double& angle = qpos[hinge.qpos_address];
      angle = std::clamp(angle, hinge.range_low_rad, hinge.range_high_rad);
    }
    clamped.push_back(KeypointPositions(character.skeleton(),
                                        character.keypoint_map(),
                                        QposToPose(character, qpos.data())));
  }
  return ProcrustesAlignedError(clamped, truth.keypoints_m);
}

}  // namespace

FitAccuracy MeasureFitAccuracy(const ViewEstimate& estimate,
                               const std::vector<PinholeCamera>& true_cameras,
                               const GroundTruth3D& truth,
                               const Character& character) {
  // Outline: check shapes; camera errors per frame (once when both are
  // static); keypoints of the fitted poses against the truth's; the
  // summary's reprojection and time.
  const int num_frames = static_cast<int>(estimate.poses.size());
  if (num_frames == 0) throw InputError(kSource, "the estimate has no poses");
  if (truth.keypoints_m.size() != estimate.poses.size()) {
    throw InputError(kSource, "the estimate has " + std::to_string(num_frames) +
                                  " poses, the truth " +
                                  std::to_string(truth.keypoints_m.size()) +
                                  " frames");
  }
  if (estimate.skeleton_name != character.skeleton().name) {
    throw InputError(
        kSource, "the estimate poses skeleton '" + estimate.skeleton_name +
                     "', the character is '" + character.skeleton().name + "'");
  }
  CheckCameraCount(estimate.cameras.size(), num_frames, "the estimate");
  CheckCameraCount(true_cameras.size(), num_frames, "the true view");

  FitAccuracy accuracy;
  accuracy.num_frames = num_frames;
  const bool both_static =
      estimate.cameras.size() == 1 && true_cameras.size() == 1;
  const int camera_frames = both_static ? 1 : num_frames;
  for (int t = 0; t < camera_frames; ++t) {
    const PinholeCamera& ours = estimate.CameraAt(t);
    const PinholeCamera& theirs =
        true_cameras.size() == 1 ? true_cameras[0] : true_cameras[t];
    const double focal = ours.intrinsics().fx_px;
    const double true_focal = theirs.intrinsics().fx_px;
    const Eigen::Vector2d angles = CameraPitchRollRad(ours);
    const Eigen::Vector2d true_angles = CameraPitchRollRad(theirs);
    accuracy.focal_error_pct +=
        100.0 * std::abs(focal - true_focal) / true_focal / camera_frames;
    accuracy.pitch_error_deg +=
        Degrees(AngleGapRad(angles[0], true_angles[0])) / camera_frames;
    accuracy.roll_error_deg +=
        Degrees(AngleGapRad(angles[1], true_angles[1])) / camera_frames;
    if (t == 0) {
      accuracy.focal_px = focal;
      accuracy.true_focal_px = true_focal;
      accuracy.pitch_deg = Degrees(angles[0]);
      accuracy.true_pitch_deg = Degrees(true_angles[0]);
      accuracy.roll_deg = Degrees(angles[1]);
      accuracy.true_roll_deg = Degrees(true_angles[1]);
    }
  }

  KeypointFrames fitted;
  fitted.reserve(num_frames);
  for (const Pose3D& pose : estimate.poses) {
    fitted.push_back(KeypointPositions(character.skeleton(),
                                       character.keypoint_map(), pose));
    if (fitted.back().size() != truth.keypoints_m.front().size()) {
      throw InputError(
          kSource, "the character has " + std::to_string(fitted.back().size()) +
                       " keypoints, the truth " +
                       std::to_string(truth.keypoints_m.front().size()));
    }
  }
  double yaw_rad = 0.0;
  accuracy.root_relative_mpjpe_mm =
      1000.0 * YawAlignedRootRelativeError(fitted, truth.keypoints_m,
                                           *truth.layout, &yaw_rad);
  double object_sum_m = 0.0;
  int num_objects = 0;
  for (const ObjectTrack3D& ours : estimate.objects) {
    const ObjectTrack3D* theirs = FindObjectTrack(truth.objects, ours.name);
    if (theirs == nullptr) continue;
    object_sum_m +=
        YawAlignedObjectError(fitted, ours.positions_m, truth.keypoints_m,
                              theirs->positions_m, *truth.layout, yaw_rad);
    ++num_objects;
  }
  if (num_objects > 0)
    accuracy.object_error_mm = 1000.0 * object_sum_m / num_objects;
  accuracy.pa_mpjpe_mm =
      1000.0 * ProcrustesAlignedError(fitted, truth.keypoints_m);
  for (double error_m :
       ProcrustesAlignedErrorPerKeypoint(fitted, truth.keypoints_m))
    accuracy.pa_per_keypoint_mm.push_back(1000.0 * error_m);
  accuracy.keypoint_names = truth.layout->keypoint_names;
  accuracy.reachable_pa_mpjpe_mm = 1000.0 * ReachableFloorM(truth, character);

  const FitSummary& summary = estimate.summary;
  accuracy.mean_reprojection_px = summary.mean_reprojection_px;
  accuracy.final_cost = summary.final_cost;
  accuracy.seconds_per_100_frames = 100.0 * summary.seconds / num_frames;
  accuracy.unconverged_fraction =
      static_cast<double>(summary.unconverged_frames.size()) / num_frames;
  return accuracy;
}

FitAccuracy MeanFitAccuracy(const std::vector<FitAccuracy>& accuracies) {
  FitAccuracy mean;
  if (accuracies.empty()) return mean;
  const double n = static_cast<double>(accuracies.size());
  double frames = 0.0;
  for (const FitAccuracy& a : accuracies) {
    frames += a.num_frames;
    mean.focal_error_pct += a.focal_error_pct / n;
    mean.pitch_error_deg += a.pitch_error_deg / n;
    mean.roll_error_deg += a.roll_error_deg / n;
    mean.focal_px += a.focal_px / n;
    mean.true_focal_px += a.true_focal_px / n;
    mean.pitch_deg += a.pitch_deg / n;
    mean.true_pitch_deg += a.true_pitch_deg / n;
    mean.roll_deg += a.roll_deg / n;
    mean.true_roll_deg += a.true_roll_deg / n;
    mean.root_relative_mpjpe_mm += a.root_relative_mpjpe_mm / n;
    mean.pa_mpjpe_mm += a.pa_mpjpe_mm / n;
    mean.reachable_pa_mpjpe_mm += a.reachable_pa_mpjpe_mm / n;
    mean.mean_reprojection_px += a.mean_reprojection_px / n;
    mean.seconds_per_100_frames += a.seconds_per_100_frames / n;
    mean.unconverged_fraction += a.unconverged_fraction / n;
    mean.cpu_seconds_per_100_frames += a.cpu_seconds_per_100_frames / n;
  }
  // Objects: the mean over the accuracies that measured one.
  int with_objects = 0;
  double object_sum_mm = 0.0;
  for (const FitAccuracy& a : accuracies) {
    if (a.object_error_mm < 0) continue;
    object_sum_mm += a.object_error_mm;
    ++with_objects;
  }
  if (with_objects > 0) mean.object_error_mm = object_sum_mm / with_objects;
  // Per keypoint: the mean when every accuracy has the same keypoints.
  mean.keypoint_names = accuracies.front().keypoint_names;
  mean.pa_per_keypoint_mm.assign(mean.keypoint_names.size(), 0.0);
  for (const FitAccuracy& a : accuracies) {
    if (a.keypoint_names != mean.keypoint_names ||
        a.pa_per_keypoint_mm.size() != mean.keypoint_names.size()) {
      mean.keypoint_names.clear();
      mean.pa_per_keypoint_mm.clear();
      break;
    }
    for (size_t j = 0; j < a.pa_per_keypoint_mm.size(); ++j)
      mean.pa_per_keypoint_mm[j] += a.pa_per_keypoint_mm[j] / n;
  }
  mean.num_frames = static_cast<int>(std::lround(frames / n));
  return mean;
}

std::string FitAccuracy::BriefReport() const {
  char line[512];
  std::snprintf(
      line, sizeof(line),
      "focal %.1f%% (%.0f px, true %.0f), pitch %.1f deg (%.1f, true %.1f), "
      "roll %.1f deg, MPJPE %.0f mm, PA-MPJPE %.0f mm (reachable %.0f), "
      "reprojection %.1f px, %.1f s/100 frames, %.0f%% unconverged",
      focal_error_pct, focal_px, true_focal_px, pitch_error_deg, pitch_deg,
      true_pitch_deg, roll_error_deg, root_relative_mpjpe_mm, pa_mpjpe_mm,
      reachable_pa_mpjpe_mm, mean_reprojection_px, seconds_per_100_frames,
      100.0 * unconverged_fraction);
  std::string report = line;
  if (object_error_mm >= 0) {
    std::snprintf(line, sizeof(line), ", object %.0f mm", object_error_mm);
    report += line;
  }
  const int worst = WorstKeypoint();
  if (worst >= 0) {
    std::snprintf(line, sizeof(line), ", worst keypoint %s (PA %.0f mm)",
                  keypoint_names[worst].c_str(), pa_per_keypoint_mm[worst]);
    report += line;
  }
  if (cpu_seconds_per_100_frames > 0) {
    std::snprintf(line, sizeof(line), " (CPU %.1f s per 100 frames)",
                  cpu_seconds_per_100_frames);
    report += line;
  }
  return report;
}

int FitAccuracy::WorstKeypoint() const {
  if (pa_per_keypoint_mm.empty() ||
      pa_per_keypoint_mm.size() != keypoint_names.size())
    return -1;
  return static_cast<int>(
      std::max_element(pa_per_keypoint_mm.begin(), pa_per_keypoint_mm.end()) -
      pa_per_keypoint_mm.begin());
}

}  // namespace m2d
