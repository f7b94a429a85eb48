#include "motion/canonical.h"

#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

Keypoint2D ToLocal(const Keypoint2D& point, const Eigen::Vector2d& root,
                   double scale) {
  return {(point.x_px - root.x()) / scale, (point.y_px - root.y()) / scale,
          point.confidence};
}

Keypoint2D FromLocal(const Keypoint2D& local, const Eigen::Vector2d& root,
                     double scale) {
  return {root.x() + scale * local.x_px, root.y() + scale * local.y_px,
          local.confidence};
}

void CheckCanonicalShapes(const CanonicalClip& canonical) {
  const std::string where = "canonical clip";
  if (canonical.layout == nullptr) throw InputError(where, "no layout");
  const size_t num_frames = static_cast<size_t>(canonical.num_frames());
  if (num_frames == 0) throw InputError(where, "no frames");
  if (canonical.local_pose.num_keypoints() !=
      canonical.layout->num_keypoints()) {
    throw InputError(
        where, "local pose has " +
                   std::to_string(canonical.local_pose.num_keypoints()) +
                   " keypoints, layout " + canonical.layout->name + " has " +
                   std::to_string(canonical.layout->num_keypoints()));
  }
  if (canonical.delta_root.size() != num_frames ||
      canonical.delta_log_scale.size() != num_frames) {
    throw InputError(where, "delta_root/delta_log_scale sizes differ from " +
                                std::to_string(num_frames) + " frames");
  }
  if (!(canonical.first_scale_px > 0.0 &&
        std::isfinite(canonical.first_scale_px))) {
    throw InputError(where, "first_scale_px must be positive");
  }
}

}  // namespace

void FrameRootsAndScales(const Clip2D& clip, const std::string& source,
                         std::vector<Eigen::Vector2d>* roots,
                         std::vector<double>* scales) {
  const int num_frames = clip.num_frames();
  std::vector<bool> usable(num_frames, false);
  roots->assign(num_frames, Eigen::Vector2d::Zero());
  scales->assign(num_frames, 0.0);
  int first_usable = -1;
  for (int t = 0; t < num_frames; ++t) {
    usable[t] = RootAndScale(clip.keypoints.frame(t), *clip.layout,
                             &(*roots)[t], &(*scales)[t]);
    if (usable[t] && first_usable < 0) first_usable = t;
  }
  if (first_usable < 0) {
    throw InputError(source,
                     "no frame has a root keypoint and 2 present keypoints; "
                     "cannot build the canonical representation");
  }
  for (int t = 0; t < num_frames; ++t) {
    if (usable[t]) continue;
    const int from = t < first_usable ? first_usable : t - 1;
    (*roots)[t] = (*roots)[from];
    (*scales)[t] = (*scales)[from];
  }
}

bool RootAndScale(const Keypoint2D* frame, const KeypointLayout& layout,
                  Eigen::Vector2d* root, double* scale) {
  Eigen::Vector2d root_sum = Eigen::Vector2d::Zero();
  int root_count = 0;
  for (int index : layout.root_keypoints) {
    if (!frame[index].IsPresent()) continue;
    root_sum += frame[index].Pixel();
    ++root_count;
  }
  if (root_count == 0) return false;
  const Eigen::Vector2d frame_root = root_sum / root_count;

  double squared_sum = 0.0;
  int present = 0;
  for (int j = 0; j < layout.num_keypoints(); ++j) {
    if (!frame[j].IsPresent()) continue;
    squared_sum += (frame[j].Pixel() - frame_root).squaredNorm();
    ++present;
  }
  if (present < 2) return false;
  const double frame_scale = std::sqrt(squared_sum / present);
  if (!(frame_scale > kMinCanonicalScalePx)) return false;
  *root = frame_root;
  *scale = frame_scale;
  return true;
}

CanonicalClip ToCanonical(const Clip2D& clip, const std::string& source) {
  ValidateClip(clip, source);
  std::vector<Eigen::Vector2d> roots;
  std::vector<double> scales;
  FrameRootsAndScales(clip, source, &roots, &scales);

  CanonicalClip canonical;
  canonical.layout = clip.layout;
  canonical.fps = clip.fps;
  canonical.image_width_px = clip.image_width_px;
  canonical.image_height_px = clip.image_height_px;
  canonical.first_root_px = roots[0];
  canonical.first_scale_px = scales[0];
  const int num_frames = clip.num_frames();
  const int num_keypoints = clip.keypoints.num_keypoints();
  canonical.local_pose = KeypointTrack(num_frames, num_keypoints);
  canonical.delta_root.assign(num_frames, Eigen::Vector2d::Zero());
  canonical.delta_log_scale.assign(num_frames, 0.0);
  for (int t = 0; t < num_frames; ++t) {
    // Missing keypoints keep their NaN coordinates and zero confidence.
    for (int j = 0; j < num_keypoints; ++j) {
      canonical.local_pose.at(t, j) =
          ToLocal(clip.keypoints.at(t, j), roots[t], scales[t]);
    }
    if (t == 0) continue;
    canonical.delta_root[t] = (roots[t] - roots[t - 1]) / scales[t];
    canonical.delta_log_scale[t] = std::log(scales[t] / scales[t - 1]);
  }
  return canonical;
}

Clip2D FromCanonical(const CanonicalClip& canonical) {
  CheckCanonicalShapes(canonical);
  Clip2D clip;
  clip.layout = canonical.layout;
  clip.fps = canonical.fps;
  clip.image_width_px = canonical.image_width_px;
  clip.image_height_px = canonical.image_height_px;
  const int num_frames = canonical.num_frames();
  const int num_keypoints = canonical.local_pose.num_keypoints();
  clip.keypoints = KeypointTrack(num_frames, num_keypoints);
  Eigen::Vector2d root = canonical.first_root_px;
  double scale = canonical.first_scale_px;
  for (int t = 0; t < num_frames; ++t) {
    if (t > 0) {
      // s_t first: the root step is normalised by the current scale.
      scale *= std::exp(canonical.delta_log_scale[t]);
      root += scale * canonical.delta_root[t];
    }
    for (int j = 0; j < num_keypoints; ++j) {
      clip.keypoints.at(t, j) =
          FromLocal(canonical.local_pose.at(t, j), root, scale);
    }
  }
  return clip;
}

}  // namespace m2d
