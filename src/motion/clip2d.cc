#include "motion/clip2d.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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

namespace {

Keypoint2D BlendKeypoints(const Keypoint2D& a, const Keypoint2D& b,
                          double alpha) {
  if (a.IsPresent() && b.IsPresent()) {
    return {a.x_px + alpha * (b.x_px - a.x_px),
            a.y_px + alpha * (b.y_px - a.y_px),
            std::min(a.confidence, b.confidence)};
  }
  const Keypoint2D& nearer = alpha < 0.5 ? a : b;
  if (nearer.IsPresent()) return nearer;
  return Keypoint2D{std::nan(""), std::nan(""), 0.0};
}

}  // namespace

Clip2D ResampleClip(const Clip2D& clip, double fps) {
  if (!(fps >= kMinClipFps && fps <= kMaxClipFps)) {
    throw ConfigError("resample: fps must be in [" +
                      std::to_string(kMinClipFps) + ", " +
                      std::to_string(kMaxClipFps) + "]");
  }
  Clip2D out = clip;
  out.fps = fps;
  const int source_frames = clip.num_frames();
  const double span_s = (source_frames - 1) / clip.fps;
  const int frames = static_cast<int>(std::floor(span_s * fps + 1e-9)) + 1;
  const int num_keypoints = clip.keypoints.num_keypoints();
  out.keypoints = KeypointTrack(frames, num_keypoints);
  for (ObjectTrack2D& object : out.objects) object.points.assign(frames, {});
  for (int t = 0; t < frames; ++t) {
    const double source = t / fps * clip.fps;
    const int before =
        std::min(static_cast<int>(std::floor(source)), source_frames - 1);
    const int after = std::min(before + 1, source_frames - 1);
    const double alpha = source - before;
    for (int j = 0; j < num_keypoints; ++j) {
      out.keypoints.at(t, j) = BlendKeypoints(
          clip.keypoints.at(before, j), clip.keypoints.at(after, j), alpha);
    }
    for (size_t o = 0; o < clip.objects.size(); ++o) {
      out.objects[o].points[t] = BlendKeypoints(
          clip.objects[o].points[before], clip.objects[o].points[after], alpha);
    }
  }
  return out;
}

Clip2D ClipFrames(const Clip2D& clip, int first, int count) {
  if (first < 0 || count < 0 || first + count > clip.num_frames()) {
    throw std::out_of_range("ClipFrames: frames [" + std::to_string(first) +
                            ", " + std::to_string(first + count) +
                            ") of a clip of " +
                            std::to_string(clip.num_frames()));
  }
  Clip2D out = clip;
  const int num_keypoints = clip.keypoints.num_keypoints();
  out.keypoints = KeypointTrack(count, num_keypoints);
  for (int t = 0; t < count; ++t) {
    for (int j = 0; j < num_keypoints; ++j)
      out.keypoints.at(t, j) = clip.keypoints.at(first + t, j);
  }
  for (size_t o = 0; o < clip.objects.size(); ++o) {
    const std::vector<Keypoint2D>& points = clip.objects[o].points;
    out.objects[o].points.assign(points.begin() + first,
                                 points.begin() + first + count);
  }
  return out;
}

}  // namespace m2d
