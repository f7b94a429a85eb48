// motion: reference bundles — one 2D clip per camera view of the same motion,
// the cameras, and (when the source was 3D) the 3D ground truth kept for
// evaluation and for initial states. Our stand-in for multi-view video.
#ifndef MIMIC2D_MOTION_BUNDLE_H_
#define MIMIC2D_MOTION_BUNDLE_H_

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "camera/pinhole.h"
#include "camera/rig.h"
#include "motion/clip2d.h"
#include "motion/motion3d.h"

namespace m2d {

struct ReferenceView {
  std::string name;
  // The true cameras: one (static) or one per clip frame (a camera that
  // moves). Empty when unknown (a user's video, `clip strip`): then only an
  // estimate (below) can project.
  std::vector<PinholeCamera> cameras;
  Clip2D clip;

  const PinholeCamera& CameraAt(int frame) const {
    return cameras.size() == 1 ? cameras[0] : cameras[frame];
  }
};

// A free object's centre (e.g. a ball's) in 3D, one per frame; `name` is
// the 2D object track's (Clip2D::objects) it is the 3D of.
struct ObjectTrack3D {
  std::string name;
  std::vector<Eigen::Vector3d> positions_m;  // T, world
};

// The track named `name` in `tracks`; null when there is none.
const ObjectTrack3D* FindObjectTrack(const std::vector<ObjectTrack3D>& tracks,
                                     const std::string& name);

// 3D truth behind a synthetic bundle, sampled at the bundle's frames.
struct GroundTruth3D {
  const KeypointLayout* layout = &Coco17Layout();
  std::vector<std::vector<Eigen::Vector3d>> keypoints_m;  // T × J, world
  // The skeleton's poses (empty when unknown); `skeleton_name` says which
  // skeleton they belong to, so a character can check it can replay them.
  std::string skeleton_name;
  std::vector<Pose3D> poses;
  std::vector<ObjectTrack3D> objects;  // the objects' 3D, when they have 2D
};

// More than this share of a view's frames unconverged makes its fit
// unreliable (FitSummary::Unreliable).
inline constexpr double kMaxUnconvergedFraction = 0.25;

// What a fit (fit/fit.h) reports for one view: a brief account of the
// solve, kept in the bundle beside the estimate it produced.
struct FitSummary {
  std::string camera_model;    // "static" or "moving"
  bool focal_fixed = false;    // --focal given: focal length not estimated
  std::string initialization;  // which start won (e.g. "facing 180 deg")
  std::string pose_prior;      // "rest" or the learned mixture's file
  int num_frames = 0;
  int iterations = 0;  // solver iterations over every stage
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double mean_reprojection_px = 0.0;    // confidence-weighted, present points
  std::vector<int> unconverged_frames;  // frames whose residual stayed high
  double seconds = 0.0;                 // wall time of the fit

  bool converged() const { return unconverged_frames.empty(); }
  // Too many frames whose residual stayed high to train on: `mimic2d fit`
  // fails, and tasks built on the estimate warn (kMaxUnconvergedFraction).
  bool Unreliable() const;
  // A few lines: iterations, cost, reprojection, frames that failed.
  std::string BriefReport() const;
};

// One view's fit, from its 2D alone: the camera and the character's pose in
// the view's own world frame (z up, ground at z = 0; the fit chooses the
// heading and horizontal origin, so two views' frames differ by a rotation
// about z and a horizontal shift).
struct ViewEstimate {
  std::vector<PinholeCamera> cameras;  // 1 (static) or one per frame
  std::string skeleton_name;           // the skeleton `poses` belong to
  std::vector<Pose3D> poses;           // one per frame
  std::vector<double> residual_px;     // per frame: mean reprojection error
  FitSummary summary;
  // The view's objects in its world frame (FitObjectTrack), one per 2D
  // object track; empty for an estimate made before objects were fitted.
  std::vector<ObjectTrack3D> objects;

  const PinholeCamera& CameraAt(int frame) const {
    return cameras.size() == 1 ? cameras[0] : cameras[frame];
  }
};

struct ReferenceBundle {
  std::string name;
  double fps = 30.0;
  std::vector<ReferenceView> views;
  // Measurement only (E3D, fit accuracy): never read in 2D-only mode.
  std::optional<GroundTruth3D> ground_truth;
  // From `mimic2d fit`: one entry per view, in view order.
  std::optional<std::vector<ViewEstimate>> estimate;
  // The views' estimates share one world (`mimic2d fit --rig`: the same
  // poses, the cameras placed together), so the views can be tracked at
  // once under the estimated cameras; false: each view's world is its own.
  bool estimate_one_world = false;

  int num_frames() const {
    return views.empty() ? 0 : views.front().clip.num_frames();
  }
};

inline constexpr char kBundleFormat[] = "mimic2d.bundle";
// Version 2 adds the `estimate` section and allows views without cameras;
// version 1 files still load.
inline constexpr int kBundleVersion = 2;

// Checks that views agree on frame count and fps, that per-frame camera
// lists match the clip length (none, 1 or T), that ground truth has the same
// length, and that an estimate has one entry per view with 1 or T cameras,
// T poses and T residuals, all finite; 3D object tracks (truth or estimate)
// name one of the first view's 2D objects each and have T finite positions.
// Errors name `source` and the view.
void ValidateBundle(const ReferenceBundle& bundle, const std::string& source);
// Reads versions 1 and 2; writes version 2 (atomically).
ReferenceBundle ReadBundle(const std::string& path);
// A bundle file, or a 2D clip file (mimic2d.clip, e.g. `mimic2d keypoints`
// output) read as a one-view bundle named after the file: what a user with
// one video has.
ReferenceBundle ReadBundleOrClip(const std::string& path);
void WriteBundle(const std::string& path, const ReferenceBundle& bundle);

// What a user with videos has: the 2D clips (image size, fps, names), with
// the ground truth, the true cameras and any estimate dropped.
ReferenceBundle StripBundle(ReferenceBundle bundle);

// How a synthetic detector corrupts projected keypoints.
struct DetectorNoiseOptions {
  double pixel_sigma_px = 0.0;      // Gaussian noise on x and y
  double drop_probability = 0.0;    // chance a keypoint is missed (conf 0)
  double time_jitter_frames = 0.0;  // std. dev. of a per-frame time offset
  uint64_t seed = 0;

  bool enabled() const {
    return pixel_sigma_px > 0 || drop_probability > 0 || time_jitter_frames > 0;
  }
  void Validate() const;  // throws ConfigError
};

// One keypoint through a synthetic detector: Gaussian noise of
// `pixel_sigma_px` on x and y, then a miss (NaN, confidence 0) with chance
// `drop_probability`. Draws only what is enabled, in that order, from the
// caller's distributions, so that a seed reproduces a clip.
void CorruptKeypoint(double pixel_sigma_px, double drop_probability,
                     std::mt19937_64& rng,
                     std::normal_distribution<double>& unit_normal,
                     std::uniform_real_distribution<double>& unit_uniform,
                     Keypoint2D* keypoint);

enum class CameraFollow {
  kStatic,     // cameras stay where the rig put them
  kRootDolly,  // cameras translate with the subject's smoothed ground path
};

// Where the rig's target sits on the ground (rig.target_m is relative to it).
enum class RigAim {
  kStartRoot,   // the subject's first root position
  kPathMiddle,  // midway between the first and last root: static cameras
                // keep a subject that travels in view and away from the lens
};

struct BundleFromMotionOptions {
  double fps = 30.0;        // frame rate of the 2D clips
  double duration_s = 0.0;  // > motion length: loop a looping motion
  LoopHeading loop_heading = LoopHeading::kAccumulate;  // across the loops
  RigOptions rig;  // rig.target_m is relative to `aim`
  RigAim aim = RigAim::kStartRoot;
  CameraFollow follow = CameraFollow::kStatic;
  double follow_smoothing_s = 1.0;  // window of the dolly's moving average
  DetectorNoiseOptions noise;

  void Validate() const;  // throws ConfigError
};

// `motion` at the bundle's frames: looped to `options.duration_s` (when a
// looping motion is shorter), resampled to `options.fps`, cut to the
// duration. What MakeBundleFromMotion renders, and what objects moving
// with the motion (sim/object_replay.h) are simulated along.
Motion3D SampleMotionForBundle(const Motion3D& motion,
                               const BundleFromMotionOptions& options);

// Renders `motion` into a multi-view bundle: forward kinematics to the
// keypoint map's 3D keypoints, projection into each rig camera, optional
// detector noise. Ground truth keeps the exact keypoints and poses.
// `objects` (3D, at SampleMotionForBundle's frames) are projected into 2D
// object tracks of every view, with the same detector noise, and kept in
// the ground truth. InputError when their frame count differs.
ReferenceBundle MakeBundleFromMotion(
    const Motion3D& motion, const KeypointMap& keypoint_map,
    const BundleFromMotionOptions& options, const std::string& name,
    const std::vector<ObjectTrack3D>& objects = {});

// Per-view figures for a one-screen summary.
struct ViewSummary {
  std::string name;
  int num_frames = 0;
  double present_fraction = 0.0;   // keypoints with confidence > 0
  double in_image_fraction = 0.0;  // present keypoints inside the image
  double mean_height_px = 0.0;     // mean vertical extent of the subject
};
std::vector<ViewSummary> SummarizeBundle(const ReferenceBundle& bundle);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_BUNDLE_H_
