// fit: estimates, from one view's 2D keypoints alone, the camera (focal
// length, pitch, roll, height; a smooth path when it moves) and the
// character's per-frame 3D pose, by robust least squares with Ceres (an
// SMPLify-like fit on our own skeleton). docs/fit.md writes out the
// objective, its terms and weights, and the staged schedule.
#ifndef MIMIC2D_FIT_FIT_H_
#define MIMIC2D_FIT_FIT_H_

#include <functional>
#include <memory>
#include <string>

#include "motion/bundle.h"
#include "motion/clip2d.h"

namespace m2d {

class Character;

enum class CameraMotion {
  kStatic,  // one camera for the whole clip (a tripod)
  kMoving,  // a smooth per-frame centre (a dolly, handheld or panning video)
};
// "static" / "moving"; false when unknown.
bool ParseCameraMotion(const std::string& text, CameraMotion* motion);
const char* CameraMotionName(CameraMotion motion);

struct FitOptions {
  CameraMotion camera_motion = CameraMotion::kStatic;
  // > 0: the focal length is known (pixels) and held fixed; 0: estimated,
  // with a prior at the image diagonal (a 53 deg diagonal field of view, as
  // CLIFF, GVHMR and WHAM assume).
  double fixed_focal_px = 0.0;

  // Data. Keypoints below this confidence are ignored.
  double min_confidence = 0.2;
  // Robust reprojection (Geman-McClure per coordinate, SMPLify's GMoF):
  // sigma in units of the person's size in the image (the RMS spread of the
  // keypoints about their root, median over frames).
  double reprojection_sigma = 0.5;

  // Weights of the terms (docs/fit.md, "Objective"), applied to residuals
  // (a cost term is 1/2 weight^2 residual^2). Residual units are in the
  // comments.
  double pose_prior_weight = 0.05;      // per hinge angle (rad) from rest
  double pose_smooth_weight = 4.0;      // hinge acceleration, rad per frame^2
  double root_smooth_weight = 20.0;     // root acceleration, m per frame^2
  double turn_smooth_weight = 8.0;      // root angular accel., rad per frame^2
  double ground_weight = 10.0;          // lowest sole point's height (m)
  double penetration_weight = 100.0;    // each sole point below z = 0 (m)
  double foot_slide_weight = 30.0;      // in-contact sole point step (m)
  double camera_smooth_weight = 400.0;  // moving centre accel., m/frame^2
  double camera_speed_weight = 0.5;     // moving centre speed, m per frame
  double focal_prior_weight = 2.0;      // log(focal / prior)
  double upright_weight = 0.5;          // root up axis, horizontal part
  // The camera's height is weakly observable when the subject stays at one
  // depth (a following camera): a prior at eye level, log(height / this).
  double camera_height_prior_m = 1.5;
  double camera_height_prior_weight = 1.0;
  // The same prior for a moving camera (spread over its centres). Stronger:
  // at one depth only height - depth x tan(pitch) is observed, and at 1 two
  // of four following views of the walk settled 0.7 m low, looking level
  // (docs/fit.md). A static camera sees the subject change depth; 5 there
  // pulled the test rig's 2.06 m camera to 1.54 m and rolled it 8-10 deg.
  double moving_camera_height_prior_weight = 5.0;
  // Soles within this height of the floor count as in contact (for the
  // foot-slide term), weight falling off as exp(-height / this).
  double contact_height_m = 0.005;
  // Sole points moving faster than this to the next frame are not in
  // contact (a landing or lifting foot).
  double contact_speed_mps = 0.5;
  int contact_rounds = 2;  // stage 3 solves, contacts relabelled before each

  // Initializations for the facing ambiguity: the character's heading is
  // tried at this many yaws evenly spaced (4: toward, away, both sides);
  // each gets stage 1 and a short stage 2, and the lowest full-pose cost
  // continues.
  int num_facing_starts = 4;
  // Solver: iterations per stage (and per round of stage 3).
  int root_stage_iterations = 20;  // stage 1, per facing start
  int screening_iterations = 10;   // stage 2's screening, per facing start
  int pose_stage_iterations = 50;
  int num_threads = 1;
  double function_tolerance = 1e-6;  // relative cost change that stops
  // A frame whose mean reprojection error exceeds this fraction of the
  // person's size did not converge (listed in the summary).
  double unconverged_residual_scale = 0.25;
  // Input checks: a clip needs this many frames; a usable frame this many
  // confident keypoints; the person at least this size (px, RMS spread);
  // at least this fraction of the frames usable.
  int min_frames = 8;
  int min_keypoints_per_frame = 6;
  double min_person_scale_px = 8.0;
  double min_usable_fraction = 0.5;
  // Called with a progress line after each stage (empty: silent).
  std::function<void(const std::string& line)> progress;

  void Validate() const;  // throws ConfigError
};

// Fits one view. `clip` is all it reads (no camera, no 3D). Throws
// InputError naming `source` for input the fit cannot use: too few frames
// or keypoints, a person a few pixels tall, coordinates far outside the
// image. A fit that does not converge everywhere still returns, with the
// frames named in summary.unconverged_frames.
ViewEstimate FitView(const Clip2D& clip, const Character& character,
                     const FitOptions& options, const std::string& source);

// Fits every view of `bundle` independently (as separate videos would be)
// and returns the bundle with its `estimate` set. `progress` (optional) is
// called after each view.
ReferenceBundle FitBundle(
    const ReferenceBundle& bundle, const Character& character,
    const FitOptions& options, const std::string& source,
    const std::function<void(int view, const ViewEstimate&)>& progress = {});

}  // namespace m2d

#endif  // MIMIC2D_FIT_FIT_H_
