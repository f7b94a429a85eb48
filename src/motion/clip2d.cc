#include "motion/clip2d.h"

#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

void ValidatePoint(const Keypoint2D& point, const std::string& source,
                   const std::string& where) {
  if (!(point.confidence >= 0.0 && point.confidence <= 1.0)) {
    throw InputError(source, where + ": confidence " +
                                 std::to_string(point.confidence) +
                                 " outside [0, 1]");
  }
  if (point.confidence > 0.0 &&
      !(std::isfinite(point.x_px) && std::isfinite(point.y_px))) {
    throw InputError(source, where +
                                 ": NaN or infinite coordinate on a keypoint "
                                 "with confidence > 0 (use confidence 0 for "
                                 "a missing keypoint)");
  }
}

}  // namespace

void ValidateClip(const Clip2D& clip, const std::string& source) {
  if (clip.layout == nullptr) throw InputError(source, "clip has no layout");
  if (!(clip.fps >= kMinClipFps && clip.fps <= kMaxClipFps)) {
    throw InputError(source, "fps " + std::to_string(clip.fps) +
                                 " is outside [" + std::to_string(kMinClipFps) +
                                 ", " + std::to_string(kMaxClipFps) + "]");
  }
  if (clip.image_width_px < 1 || clip.image_height_px < 1 ||
      clip.image_width_px > kMaxImageSidePx ||
      clip.image_height_px > kMaxImageSidePx) {
    throw InputError(source, "image size must be in [1, " +
                                 std::to_string(kMaxImageSidePx) + "] px");
  }
  if (clip.num_frames() < 1) throw InputError(source, "clip has no frames");
  if (clip.keypoints.num_keypoints() != clip.layout->num_keypoints()) {
    throw InputError(
        source, "clip has " + std::to_string(clip.keypoints.num_keypoints()) +
                    " keypoints per frame but layout '" + clip.layout->name +
                    "' has " + std::to_string(clip.layout->num_keypoints()));
  }
  for (int t = 0; t < clip.num_frames(); ++t) {
    for (int j = 0; j < clip.keypoints.num_keypoints(); ++j) {
      ValidatePoint(clip.keypoints.at(t, j), source,
                    "frame " + std::to_string(t) + " keypoint '" +
                        clip.layout->keypoint_names[j] + "'");
    }
  }
  for (const ObjectTrack2D& object : clip.objects) {
    if (static_cast<int>(object.points.size()) != clip.num_frames()) {
      throw InputError(source, "object '" + object.name + "' has " +
                                   std::to_string(object.points.size()) +
                                   " frames, clip has " +
                                   std::to_string(clip.num_frames()));
    }
    for (int t = 0; t < clip.num_frames(); ++t) {
      ValidatePoint(object.points[t], source,
                    "object '" + object.name + "' frame " + std::to_string(t));
    }
  }
}

}  // namespace m2d
