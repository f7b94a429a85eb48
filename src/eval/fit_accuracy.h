// eval: how well a fit (fit/fit.h) recovered one view's camera and 3D poses,
// measured against the truth that the fit never saw (a synthetic bundle's
// true cameras and GroundTruth3D). A pure function; `mimic2d bench fit`
// (eval/fit_benchmark.h) tabulates it over clips and camera settings.
#ifndef MIMIC2D_EVAL_FIT_ACCURACY_H_
#define MIMIC2D_EVAL_FIT_ACCURACY_H_

#include <string>
#include <vector>

#include "camera/pinhole.h"
#include "motion/bundle.h"

namespace m2d {

class Character;

struct FitAccuracy {
  int num_frames = 0;
  // Camera, mean over frames of the absolute error (a static camera is
  // compared once): |f_est - f_true| / f_true in percent; pitch and roll
  // (fit/camera_model.h's CameraPitchRollRad, wrapped to +-180) in degrees.
  double focal_error_pct = 0.0;
  double pitch_error_deg = 0.0;
  double roll_error_deg = 0.0;
  // Frame 0's values, for the record.
  double focal_px = 0.0, true_focal_px = 0.0;
  double pitch_deg = 0.0, true_pitch_deg = 0.0;
  double roll_deg = 0.0, true_roll_deg = 0.0;
  // Poses, from the fitted poses' keypoints (KeypointPositions) against the
  // truth's keypoints_m, in millimetres: root-relative MPJPE after the best
  // single rotation about z (the fit's heading is its own), and PA-MPJPE
  // (per-frame similarity alignment).
  double root_relative_mpjpe_mm = 0.0;
  double pa_mpjpe_mm = 0.0;
  // The floor a fit on this character can reach: PA-MPJPE of the true
  // poses with every hinge clamped to the character's range (a DeepMimic
  // clip may bend joints further than the simulated character can; the
  // fit holds its poses inside the ranges). 0 without true poses.
  double reachable_pa_mpjpe_mm = 0.0;
  // PA-MPJPE per keypoint (mm, the truth's layout order) and those
  // keypoints' names: a limb fitted in its depth-mirrored solution (it
  // projects alike) shows as its end far above the rest, which the mean
  // hides.
  std::vector<double> pa_per_keypoint_mm;
  std::vector<std::string> keypoint_names;
  // Objects (a ball): the fitted centre's offset from the character's root
  // against the truth's, after the root-relative error's rotation about z
  // (YawAlignedObjectError), mean over objects and frames, in millimetres;
  // -1 when the truth or the estimate has no objects.
  double object_error_mm = -1.0;
  // From the fit's summary: confidence-weighted mean reprojection (px), wall
  // time scaled to 100 frames (s), share of frames that did not converge.
  double mean_reprojection_px = 0.0;
  double seconds_per_100_frames = 0.0;
  double unconverged_fraction = 0.0;
  double final_cost = 0.0;  // the fit's objective at its end
  // CPU time of the fit (all threads) scaled to 100 frames (s): robust to
  // other work sharing the cores. Set by a caller that timed the fit (the
  // benchmark); 0 when not measured.
  double cpu_seconds_per_100_frames = 0.0;

  // One line: camera errors, pose errors, reprojection, time.
  std::string BriefReport() const;
  // The keypoint with the largest PA error; -1 without per-keypoint errors.
  int WorstKeypoint() const;
};

// Measures `estimate` (one view's fit) against that view's true cameras (1
// or one per frame), the bundle's truth and the character the fit posed.
// Throws InputError when the shapes disagree (frame counts, camera counts,
// a skeleton other than the character's).
FitAccuracy MeasureFitAccuracy(const ViewEstimate& estimate,
                               const std::vector<PinholeCamera>& true_cameras,
                               const GroundTruth3D& truth,
                               const Character& character);

// Field-by-field mean (frame 0 values included); {} for an empty list.
FitAccuracy MeanFitAccuracy(const std::vector<FitAccuracy>& accuracies);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_FIT_ACCURACY_H_
