// motion: the 2D clip — T frames × J keypoints × (x, y, confidence).
#ifndef MIMIC2D_MOTION_CLIP2D_H_
#define MIMIC2D_MOTION_CLIP2D_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "motion/layout.h"

namespace m2d {

// One detected keypoint in pixels. A keypoint is *missing* when its
// confidence is 0 or any coordinate is NaN; every consumer must skip it.
struct Keypoint2D {
  double x_px = 0.0;
  double y_px = 0.0;
  double confidence = 0.0;  // in [0, 1]; 0 means not detected

  bool IsPresent() const {
    return confidence > 0.0 && x_px == x_px && y_px == y_px;
  }
  Eigen::Vector2d Pixel() const { return {x_px, y_px}; }
};

// A T × J grid of keypoints, stored frame-major.
class KeypointTrack {
 public:
  KeypointTrack() = default;
  KeypointTrack(int num_frames, int num_keypoints)
      : num_frames_(num_frames),
        num_keypoints_(num_keypoints),
        points_(static_cast<size_t>(num_frames) * num_keypoints) {}

  int num_frames() const { return num_frames_; }
  int num_keypoints() const { return num_keypoints_; }
  Keypoint2D& at(int frame, int keypoint) {
    return points_[static_cast<size_t>(frame) * num_keypoints_ + keypoint];
  }
  const Keypoint2D& at(int frame, int keypoint) const {
    return points_[static_cast<size_t>(frame) * num_keypoints_ + keypoint];
  }
  // Pointer to frame `frame`'s J keypoints.
  const Keypoint2D* frame(int frame) const {
    return points_.data() + static_cast<size_t>(frame) * num_keypoints_;
  }

 private:
  int num_frames_ = 0;
  int num_keypoints_ = 0;
  std::vector<Keypoint2D> points_;
};

// A tracked object's 2D positions (e.g. a soccer ball), one per frame.
struct ObjectTrack2D {
  std::string name;                // e.g. "ball"
  std::vector<Keypoint2D> points;  // one per clip frame
};

struct Clip2D {
  const KeypointLayout* layout = &Coco17Layout();
  double fps = 30.0;
  int image_width_px = 1920;
  int image_height_px = 1080;
  KeypointTrack keypoints;  // num_keypoints == layout->num_keypoints()
  std::vector<ObjectTrack2D> objects;

  int num_frames() const { return keypoints.num_frames(); }
  double duration_s() const { return num_frames() / fps; }
};

// Plausible bounds of a recording: anything outside is a broken file (fuzzing
// found 1e-320 and 1e308 fps accepted, and image sides past 2^31 wrapped).
inline constexpr double kMinClipFps = 1.0;
inline constexpr double kMaxClipFps = 1000.0;
inline constexpr long kMaxImageSidePx = 65536;

// Checks the invariants above (fps and image size within the bounds above,
// matching shapes,
// confidences in [0, 1], no NaN on a keypoint with confidence > 0, at least
// one frame). Throws InputError with `source` (a file name) on failure.
void ValidateClip(const Clip2D& clip, const std::string& source);

// The clip at another frame rate (e.g. a 10 fps video to the 30 Hz control
// rate), frame t at time t / fps over the same span: each keypoint (and
// object point) interpolated linearly between the two source frames around
// it when both have it (confidence: the lesser), the nearer one's
// otherwise; missing when neither does.
Clip2D ResampleClip(const Clip2D& clip, double fps);

// Frames [first, first + count) of `clip` (objects too), e.g. a stretch to
// fit again alone. Throws std::out_of_range when they are not all in it.
Clip2D ClipFrames(const Clip2D& clip, int first, int count);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_CLIP2D_H_
