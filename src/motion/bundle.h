// motion: reference bundles — one 2D clip per camera view of the same motion,
// the cameras, and (when the source was 3D) the 3D ground truth kept for
// evaluation and for initial states. Our stand-in for multi-view video.
#ifndef MIMIC2D_MOTION_BUNDLE_H_
#define MIMIC2D_MOTION_BUNDLE_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "camera/pinhole.h"
#include "camera/rig.h"
#include "motion/clip2d.h"
#include "motion/motion3d.h"

namespace m2d {

struct ReferenceView {
  std::string name;
  // One camera (static) or one per clip frame (a camera that moves).
  std::vector<PinholeCamera> cameras;
  Clip2D clip;

  const PinholeCamera& CameraAt(int frame) const {
    return cameras.size() == 1 ? cameras[0] : cameras[frame];
  }
};

// 3D truth behind a synthetic bundle, sampled at the bundle's frames.
struct GroundTruth3D {
  const KeypointLayout* layout = &Coco17Layout();
  std::vector<std::vector<Eigen::Vector3d>> keypoints_m;  // T × J, world
  // The skeleton's poses (empty when unknown); `skeleton_name` says which
  // skeleton they belong to, so a character can check it can replay them.
  std::string skeleton_name;
  std::vector<Pose3D> poses;
};

struct ReferenceBundle {
  std::string name;
  double fps = 30.0;
  std::vector<ReferenceView> views;
  std::optional<GroundTruth3D> ground_truth;

  int num_frames() const {
    return views.empty() ? 0 : views.front().clip.num_frames();
  }
};

inline constexpr char kBundleFormat[] = "mimic2d.bundle";
inline constexpr int kBundleVersion = 1;

// Checks that views agree on frame count and fps, that per-frame camera
// lists match the clip length, and that ground truth has the same length.
void ValidateBundle(const ReferenceBundle& bundle, const std::string& source);
ReferenceBundle ReadBundle(const std::string& path);
void WriteBundle(const std::string& path, const ReferenceBundle& bundle);

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

enum class CameraFollow {
  kStatic,     // cameras stay where the rig put them
  kRootDolly,  // cameras translate with the subject's smoothed ground path
};

struct BundleFromMotionOptions {
  double fps = 30.0;        // frame rate of the 2D clips
  double duration_s = 0.0;  // > motion length: loop a looping motion
  RigOptions rig;           // rig.target_m is relative to the start root
  CameraFollow follow = CameraFollow::kStatic;
  double follow_smoothing_s = 1.0;  // window of the dolly's moving average
  DetectorNoiseOptions noise;

  void Validate() const;  // throws ConfigError
};

// Renders `motion` into a multi-view bundle: forward kinematics to the
// keypoint map's 3D keypoints, projection into each rig camera, optional
// detector noise. Ground truth keeps the exact keypoints and poses.
ReferenceBundle MakeBundleFromMotion(const Motion3D& motion,
                                     const KeypointMap& keypoint_map,
                                     const BundleFromMotionOptions& options,
                                     const std::string& name);

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
