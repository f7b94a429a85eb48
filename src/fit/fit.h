// fit: estimates, from one view's 2D keypoints alone, the camera (focal
// length, pitch, roll, height; a smooth path when it moves) and the
// character's per-frame 3D pose, by robust least squares with Ceres (an
// SMPLify-like fit on our own skeleton). docs/fit.md writes out the
// objective, its terms and weights, and the staged schedule.
#ifndef MIMIC2D_FIT_FIT_H_
#define MIMIC2D_FIT_FIT_H_

#include <array>
#include <functional>
#include <memory>
#include <string>

#include "common/settings.h"
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
// As a setting (common/settings.h).
inline const char* SettingName(CameraMotion motion) {
  return CameraMotionName(motion);
}
inline bool ParseSetting(const std::string& text, CameraMotion* motion) {
  return ParseCameraMotion(text, motion);
}
inline std::string SettingChoices(CameraMotion) { return "static, moving"; }

// The fit's pose prior: the character's learned mixture over its hinge
// angles (fit/pose_prior.h, its config's `pose_prior`), or a pull toward the
// rest pose; auto takes the mixture when the character has one.
enum class PosePriorKind { kAuto, kMixture, kRest };
inline const char* SettingName(PosePriorKind kind) {
  return kind == PosePriorKind::kMixture ? "mixture"
         : kind == PosePriorKind::kRest  ? "rest"
                                         : "auto";
}
inline bool ParseSetting(const std::string& text, PosePriorKind* kind) {
  return ParseSettingByName(
      text,
      {PosePriorKind::kAuto, PosePriorKind::kMixture, PosePriorKind::kRest},
      kind);
}
inline std::string SettingChoices(PosePriorKind) {
  return "auto, mixture, rest";
}

struct FitOptions {
  CameraMotion camera_motion = CameraMotion::kStatic;
  // > 0: the focal length is known (pixels) and held fixed; 0: estimated,
  // with a prior at the image diagonal (a 53 deg diagonal field of view, as
  // CLIFF, GVHMR and WHAM assume).
  double fixed_focal_px = 0.0;
  // true: the camera's tilt is known and held, pitch at known_pitch_deg
  // (positive looks down) and roll at known_roll_deg; false: both
  // estimated from the pitch starts. For clips whose view was chosen, not
  // filmed: `generate --policy` fits the start of a clip it generated under
  // --view, whose tilt the 2D only approximates (docs/fit.md, "A known
  // tilt").
  bool tilt_known = false;
  double known_pitch_deg = 0.0;
  double known_roll_deg = 0.0;

  // Data. Keypoints below this confidence are ignored.
  double min_confidence = 0.2;
  // Robust reprojection (Geman-McClure per coordinate, SMPLify's GMoF):
  // sigma in units of the person's size in the image (the RMS spread of the
  // keypoints about their root, median over frames).
  double reprojection_sigma = 0.5;

  // Weights of the terms (docs/fit.md, "Objective"), applied to residuals
  // (a cost term is 1/2 weight^2 residual^2). Residual units are in the
  // comments.
  PosePriorKind pose_prior = PosePriorKind::kAuto;
  double pose_prior_weight = 0.05;  // per hinge angle (rad) from rest
  // The learned prior's weight, per standard deviation of its best
  // component (its cost is weight^2 x the mixture's negative
  // log-likelihood; docs/fit.md for the value).
  double pose_mixture_weight = 0.05;
  // The same in stage 3 (contacts): SMPLify's schedule lowers the prior
  // once the pose is in the right basin, so the 2D has the last word.
  double pose_mixture_final_weight = 0.02;
  double pose_smooth_weight = 4.0;  // hinge acceleration, rad per frame^2
  // Stage 4 (refine: the camera held) lowers both once more. The 2D term's
  // residuals are in person sizes (a 4-px error on a 100-px person is
  // 0.04), so at smoothness 4 a real kick's accelerations cost hundreds of
  // times its 2D error and the fit smoothed motion away (6-10 px off on the
  // run, kick and dance). Lowered in stage 3 the camera drifts with the
  // freer pose, hence a stage of its own (docs/fit.md, "Smoothness and the
  // refinement").
  double refine_smooth_weight = 0.5;    // hinge acceleration, rad/frame^2
  double refine_mixture_weight = 0.01;  // learned prior, per std. dev.
  double root_smooth_weight = 20.0;     // root acceleration, m per frame^2
  double turn_smooth_weight = 8.0;      // root angular accel., rad per frame^2
  double ground_weight = 10.0;          // lowest sole point's height (m)
  double penetration_weight = 100.0;    // each sole point below z = 0 (m)
  // Two of the character's collision spheres overlapping (m): legs and arms
  // that 2D alone lets pass through each other or the trunk. Pairs closer
  // than self_contact_margin_m when a stage's solve is built are watched.
  double self_contact_weight = 20.0;
  double self_contact_margin_m = 0.05;
  double foot_slide_weight = 30.0;      // in-contact sole point step (m)
  double camera_smooth_weight = 400.0;  // moving centre accel., m/frame^2
  double camera_speed_weight = 0.5;     // moving centre speed, m per frame
  double focal_prior_weight = 2.0;      // log(focal / prior)
  double upright_weight = 0.5;          // root up axis, horizontal part
  // The same in a rig of moving cameras' joint stages (FitRig; each view's
  // own fit keeps upright_weight). One view cannot tell a leaning body from
  // a tilted camera, and the term holds the body upright; a rig's views pin
  // the pose, and the term then tilts the whole world under a body that
  // really leans (a stealthy walk: 8 deg at 0.5, 0.2 at 0; docs/fit.md,
  // "A rig").
  double moving_rig_upright_weight = 0.0;
  double camera_roll_prior_weight = 0.0;  // camera roll (rad) from level
  // Balance (stage 3, frames with a sole in contact): the zero-moment point
  // outside the in-contact soles' box grown by the margin (m); the centre
  // of mass's acceleration over +-balance_span_s. Off by default: on
  // static, focal-known views it tilts the fitted world (docs/fit.md,
  // "Balance").
  double balance_weight = 0.0;
  double balance_margin_m = 0.05;
  double balance_span_s = 0.1;
  // Balance on average (stages 3-4, costs.h LeanCost): over each
  // window of this many seconds, the mean horizontal offset (m) of the
  // centre of mass from the in-contact soles. Unlike the zero-moment point
  // it needs no accelerations and no support polygon: a body stands over
  // its feet on average (docs/fit.md, "Balance on average"). On by default
  // for a static camera (with the 2D's contacts and ground below: pitch
  // and roll 6.1 / 8.3 -> 3.9 / 3.9 deg on the accuracy table's static
  // rig); off for a moving one, where it cost the following walk's tracker
  // a view (docs/fit.md, "Static-camera cues").
  double mean_balance_weight = 3.0;
  double moving_camera_mean_balance_weight = 0.0;
  double mean_balance_window_s = 2.0;
  // The camera's height is weakly observable when the subject stays at one
  // depth (a following camera): a prior at eye level, log(height / this).
  double camera_height_prior_m = 1.5;
  double camera_height_prior_weight = 1.0;
  // The same prior for a moving camera (spread over its centres). At one
  // depth only height - depth x tan(pitch) is observed; at 5 (before the
  // pitch starts) it held a following 25-deg camera at eye level, looking
  // level at a leaning body (docs/fit.md, schedule step 3).
  double moving_camera_height_prior_weight = 1.0;
  // Soles within this height of the floor count as in contact (for the
  // foot-slide term), weight falling off as exp(-height / this).
  double contact_height_m = 0.005;
  // Sole points moving faster than this to the next frame are not in
  // contact (a landing or lifting foot).
  double contact_speed_mps = 0.5;
  // Static camera: a sole is still when its foot's observed 2D ankle moves
  // slower than contact_speed_mps at the person's image scale, instead of
  // when the fitted foot does (docs/fit.md, "Contacts from the 2D").
  bool contacts_from_2d = true;
  // Static camera: the ground term only in frames where a foot can stand,
  // those where some foot's observed 2D ankle is still (as above) over a
  // central difference of +-ground_still_span_s (the faster half where the
  // halves turn back, as at a flight's top), or unseen; where every
  // foot is seen moving (a jump's flight) only the penetration term holds
  // the feet. Off: every frame (docs/fit.md, "Ground where a foot is
  // still").
  bool ground_from_2d = true;
  double ground_still_span_s = 0.1;  // longer than a frame: detector noise
  // A frame this close to a still one keeps the ground term too: an ankle
  // rolls over its planted foot early and late in a stance (without the
  // margin 6 of a run's 24 frames kept it, though it is airborne in few).
  double ground_margin_s = 0.1;
  int contact_rounds = 2;  // stage 3 solves, contacts relabelled before each

  // Initializations for the facing ambiguity: the character's heading is
  // tried at this many yaws evenly spaced (4: toward, away, both sides);
  // each gets stage 1 and a short stage 2, and the lowest full-pose cost
  // continues.
  int num_facing_starts = 4;
  // Camera pitches (deg, positive looks down) the search starts from: every
  // facing start at the first, then the best facing at each of the others;
  // the lowest full-pose cost continues.
  std::vector<double> pitch_starts_deg = {0.0, 20.0, 40.0};
  // Solver: iterations per stage (and per round of stage 3).
  int root_stage_iterations = 20;  // stage 1, per facing start
  int limb_search_iterations = 5;  // per limb start and frame; 0: off
  int screening_iterations = 10;   // stage 2's screening, per facing start
  int pose_stage_iterations = 50;
  int refine_iterations = 50;  // stage 4; 0: no refinement
  // Stage 5 (one view, not a rig): stretches of frames whose mean
  // reprojection error exceeds this fraction of the person's size after
  // stage 4 are fitted again as a clip of their own, with this many frames
  // of context on each side, and spliced in where they explain the 2D
  // better (a window over half the clip is skipped); stages 2-4 then run
  // again over the whole clip. A long clip's one start and smooth terms can
  // hold a stretch in a wrong basin (the stealthy walk's side views:
  // stretches of 25-131 frames at 17-25 px beside 0.7 px elsewhere). 0: off.
  double window_refit_residual_scale = 0.1;
  int window_refit_context_frames = 45;
  int num_threads = 1;
  double function_tolerance = 1e-6;  // relative cost change that stops
  // A frame whose mean reprojection error exceeds this fraction of the
  // person's size did not converge (listed in the summary).
  double unconverged_residual_scale = 0.25;
  // Input checks: a clip needs this many frames; a usable frame this many
  // confident keypoints; the person at least this size (px, RMS spread);
  // at least this fraction of the frames usable.
  // Objects (a clip's object tracks, e.g. a ball) are placed after the
  // character, on the plane one radius above the floor under the fitted
  // camera: a rolling ball (motion/object_track.h). A size-5 soccer ball's
  // radius, as assets/characters/soccer_ball.xml.
  double object_radius_m = 0.11;
  double object_deceleration_m_s2 = 0.45;  // rolling on out of the image

  int min_frames = 8;
  int min_keypoints_per_frame = 6;
  double min_person_scale_px = 8.0;
  double min_usable_fraction = 0.5;
  // Called with a progress line after each stage (empty: silent).
  std::function<void(const std::string& line)> progress;

  // Every setting of `mimic2d fit --config` (common/settings.h); the
  // reasons for the defaults are in the comments above.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    const Range weight = Range::AtLeast(0);
    v("camera_motion", self.camera_motion, Range::Any(),
      "a tripod (one camera) or a smooth per-frame centre");
    v("fixed_focal_px", self.fixed_focal_px, Range::AtLeast(0),
      "> 0: the known focal length (px), held fixed; 0: estimated");
    v("tilt_known", self.tilt_known, Range::Any(),
      "true: the camera's pitch and roll are known_pitch_deg and "
      "known_roll_deg, held fixed; false: estimated");
    v("known_pitch_deg", self.known_pitch_deg, Range::Closed(-74, 74),
      "with tilt_known: the camera's pitch (deg, positive looks down)");
    v("known_roll_deg", self.known_roll_deg, Range::Closed(-40, 40),
      "with tilt_known: the camera's roll about its optical axis (deg)");
    v("min_confidence", self.min_confidence, Range::Closed(0, 1),
      "keypoints below this confidence are ignored");
    v("reprojection_sigma", self.reprojection_sigma, Range::Above(0),
      "Geman-McClure sigma of the 2D term, in person sizes");
    v("pose_prior", self.pose_prior, Range::Any(),
      "the character's learned pose mixture, or toward rest");
    v("pose_mixture_weight", self.pose_mixture_weight, weight,
      "learned prior, per standard deviation");
    v("pose_mixture_final_weight", self.pose_mixture_final_weight, weight,
      "learned prior in stage 3 (contacts)");
    v("pose_prior_weight", self.pose_prior_weight, weight,
      "per hinge angle (rad) from rest");
    v("pose_smooth_weight", self.pose_smooth_weight, weight,
      "hinge acceleration (rad per frame^2)");
    v("refine_smooth_weight", self.refine_smooth_weight, weight,
      "hinge acceleration in stage 4 (refine, camera held)");
    v("refine_mixture_weight", self.refine_mixture_weight, weight,
      "learned prior in stage 4 (refine, camera held)");
    v("root_smooth_weight", self.root_smooth_weight, weight,
      "root acceleration (m per frame^2)");
    v("turn_smooth_weight", self.turn_smooth_weight, weight,
      "root angular acceleration (rad per frame^2)");
    v("ground_weight", self.ground_weight, weight,
      "lowest sole point's height (m)");
    v("penetration_weight", self.penetration_weight, weight,
      "each sole point below the floor (m)");
    v("self_contact_weight", self.self_contact_weight, weight,
      "two of the character's collision spheres overlapping (m): a leg or "
      "arm through another or through the trunk; 0: off");
    v("self_contact_margin_m", self.self_contact_margin_m, Range::AtLeast(0),
      "sphere pairs closer than this when a stage's solve is built are "
      "watched for overlap (m)");
    v("foot_slide_weight", self.foot_slide_weight, weight,
      "in-contact sole point's step (m)");
    v("camera_smooth_weight", self.camera_smooth_weight, weight,
      "moving camera centre's acceleration (m per frame^2)");
    v("camera_speed_weight", self.camera_speed_weight, weight,
      "moving camera centre's speed (m per frame)");
    v("focal_prior_weight", self.focal_prior_weight, weight,
      "log(focal / prior at the image diagonal)");
    v("upright_weight", self.upright_weight, weight,
      "horizontal part of the root's up axis");
    v("moving_rig_upright_weight", self.moving_rig_upright_weight, weight,
      "the same in a rig of moving cameras' joint stages");
    v("camera_roll_prior_weight", self.camera_roll_prior_weight, weight,
      "camera roll (rad) from level");
    v("balance_weight", self.balance_weight, weight,
      "zero-moment point outside the contact soles' box (m)");
    v("balance_margin_m", self.balance_margin_m, Range::AtLeast(0),
      "the support box grown by this (m)");
    v("balance_span_s", self.balance_span_s, Range::Above(0),
      "centre-of-mass acceleration over +- this (s)");
    v("mean_balance_weight", self.mean_balance_weight, weight,
      "mean centre-of-mass offset from the contact soles per window (m), "
      "static camera");
    v("moving_camera_mean_balance_weight",
      self.moving_camera_mean_balance_weight, weight,
      "the same, moving camera");
    v("mean_balance_window_s", self.mean_balance_window_s, Range::Above(0),
      "window of the mean balance (s)");
    v("camera_height_prior_m", self.camera_height_prior_m, Range::Above(0),
      "camera height prior (m), eye level");
    v("camera_height_prior_weight", self.camera_height_prior_weight, weight,
      "log(height / prior), static camera");
    v("moving_camera_height_prior_weight",
      self.moving_camera_height_prior_weight, weight,
      "log(height / prior), moving camera");
    v("contact_height_m", self.contact_height_m, Range::Above(0),
      "soles within this height are in contact (m)");
    v("contact_speed_mps", self.contact_speed_mps, Range::Above(0),
      "soles faster than this are not in contact (m/s)");
    v("contacts_from_2d", self.contacts_from_2d, Range::Any(),
      "static camera: stillness seen on the 2D ankle, not the fitted foot");
    v("ground_from_2d", self.ground_from_2d, Range::Any(),
      "static camera: the ground term only where a 2D ankle is still");
    v("ground_still_span_s", self.ground_still_span_s, Range::Above(0),
      "half-span of the 2D ankle's stillness test for the ground term (s)");
    v("ground_margin_s", self.ground_margin_s, Range::AtLeast(0),
      "frames this close to a still one keep the ground term (s)");
    v("contact_rounds", self.contact_rounds, Range::Closed(1, 100),
      "full-pose solves, contacts relabelled before each");
    v("num_facing_starts", self.num_facing_starts, Range::Closed(1, 16),
      "headings tried for the facing ambiguity");
    v("pitch_starts_deg", self.pitch_starts_deg, Range::Closed(-60, 60),
      "camera pitches (deg) the search starts from; the first for every "
      "facing start");
    v("root_stage_iterations", self.root_stage_iterations,
      Range::Closed(1, 100000), "stage 1 iterations per facing start");
    v("limb_search_iterations", self.limb_search_iterations,
      Range::Closed(0, 1000),
      "stage 1b iterations per limb start and frame (0: no limb search)");
    v("screening_iterations", self.screening_iterations,
      Range::Closed(1, 100000), "stage 2 screening iterations per start");
    v("pose_stage_iterations", self.pose_stage_iterations,
      Range::Closed(1, 100000), "full-pose iterations per round");
    v("refine_iterations", self.refine_iterations, Range::Closed(0, 100000),
      "stage 4 iterations (0: no refinement)");
    v("window_refit_residual_scale", self.window_refit_residual_scale,
      Range::AtLeast(0),
      "stage 5: stretches whose mean error exceeds this many person sizes "
      "are fitted again alone and spliced in (0: off)");
    v("window_refit_context_frames", self.window_refit_context_frames,
      Range::Closed(0, 100000),
      "stage 5: frames of context on each side of a stretch fitted again");
    v("num_threads", self.num_threads, Range::Closed(1, 1024), "Ceres threads");
    v("function_tolerance", self.function_tolerance, Range::Above(0),
      "relative cost change that stops a solve");
    v("unconverged_residual_scale", self.unconverged_residual_scale,
      Range::Above(0),
      "a frame with mean error above this many person sizes did not "
      "converge");
    v("object_radius_m", self.object_radius_m, Range::Above(0),
      "tracked objects are balls of this radius rolling on the floor (m)");
    v("object_deceleration_m_s2", self.object_deceleration_m_s2,
      Range::Above(0),
      "a ball that left the image rolls on, slowing by this (m/s^2)");
    v("min_frames", self.min_frames, Range::AtLeast(3),
      "a clip needs this many frames");
    v("min_keypoints_per_frame", self.min_keypoints_per_frame,
      Range::Closed(4, 17), "confident keypoints a usable frame needs");
    v("min_person_scale_px", self.min_person_scale_px, Range::Above(0),
      "smallest person (px, RMS spread about the root)");
    v("min_usable_fraction", self.min_usable_fraction,
      Range{0, 1, /*min_open=*/true, /*max_open=*/false},
      "share of usable frames a clip needs");
  }
  void Validate() const;  // throws ConfigError
};

// Fits one view. `clip` is all it reads (no camera, no 3D). Throws
// InputError naming `source` for input the fit cannot use: too few frames
// or keypoints, a person a few pixels tall, coordinates far outside the
// image. A fit that does not converge everywhere still returns, with the
// frames named in summary.unconverged_frames.
ViewEstimate FitView(const Clip2D& clip, const Character& character,
                     const FitOptions& options, const std::string& source);

// Stages 2 to 4 of the fit (full pose, contacts, refinement) started from given
// cameras (1, or one per frame) and poses instead of the fit's own start
// (hinges clamped into their ranges; the focal held when options.fixed_focal_px
// says so). For diagnosis: started at the truth (`mimic2d bench fit
// --from-truth`) it tells a search that misses from an objective whose minimum
// is off the truth. summary.initial_cost is the start's cost under stage 2's
// objective. Throws InputError as FitView does, or when `poses` or
// `cameras` do not match the frames.
ViewEstimate RefineView(const Clip2D& clip, const Character& character,
                        const FitOptions& options,
                        const std::vector<PinholeCamera>& cameras,
                        const std::vector<Pose3D>& poses,
                        const std::string& source);

// The objective's terms (docs/fit.md, "Objective"), for a breakdown of its
// cost.
enum class FitTerm {
  kReprojection,
  kGround,
  kPenetration,
  kUpright,
  kRootSmooth,
  kTurnSmooth,
  kPosePrior,  // the learned mixture, or the pull toward rest
  kPoseSmooth,
  kFootSlide,
  kBalance,
  kMeanBalance,
  kFocalPrior,
  kCameraRollPrior,
  kCameraHeightPrior,
  kCameraSpeed,
  kCameraSmooth,
  kSelfContact,
};
inline constexpr int kNumFitTerms = 17;
const char* FitTermName(FitTerm term);

// An objective's cost at one state, term by term (each 1/2 the sum of its
// squared residuals; their sum is the cost Ceres reports).
struct FitTermCosts {
  std::array<double, kNumFitTerms> cost{};

  double& operator[](FitTerm term) { return cost[static_cast<int>(term)]; }
  double operator[](FitTerm term) const { return cost[static_cast<int>(term)]; }
  double Total() const;
  // "reprojection 0.12, ground 0.031, ...; total 0.2": the terms above 0.
  std::string BriefReport() const;
};

// Stage 3's objective (the one that settles the camera: the full pose, feet
// that do not slide at the state's own contacts) at given cameras (1, or one
// per frame) and poses, term by term, with no iterations. For diagnosis
// (`mimic2d bench fit --from-truth`): at the truth and at a fit it says which
// terms prefer the fit. Throws InputError as RefineView does.
FitTermCosts ExplainCost(const Clip2D& clip, const Character& character,
                         const FitOptions& options,
                         const std::vector<PinholeCamera>& cameras,
                         const std::vector<Pose3D>& poses,
                         const std::string& source);

// Fits every view of `bundle` independently (as separate videos would be)
// and returns the bundle with its `estimate` set. `progress` (optional) is
// called after each view.
ReferenceBundle FitBundle(
    const ReferenceBundle& bundle, const Character& character,
    const FitOptions& options, const std::string& source,
    const std::function<void(int view, const ViewEstimate&)>& progress = {});

// Fits the views of `bundle` as one synchronized take of static cameras (a
// calibrated rig: `mimic2d fit --rig`): one body seen by every camera, each
// camera with its own pitch, roll, yaw and position (the focal as
// options.fixed_focal_px says), from the 2D alone. Starts from each view's
// own fit (FitView); every view's estimate then holds its camera and the
// same poses, in one world. Throws ConfigError for a moving camera and
// InputError for fewer than 2 views or views of different lengths.
// `progress` is called per view at the end.
ReferenceBundle FitRig(
    const ReferenceBundle& bundle, const Character& character,
    const FitOptions& options, const std::string& source,
    const std::function<void(int view, const ViewEstimate&)>& progress = {});

}  // namespace m2d

#endif  // MIMIC2D_FIT_FIT_H_
