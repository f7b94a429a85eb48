// motion: the paper's canonical 2D representation — per frame a local pose
// x̄ = (x − root) / s plus the normalised root step and log-scale step —
// and its exact inverse.
#ifndef MIMIC2D_MOTION_CANONICAL_H_
#define MIMIC2D_MOTION_CANONICAL_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "motion/clip2d.h"

namespace m2d {

// Scales at or below this are degenerate (all present keypoints on the
// root), so the frame gets no root/scale of its own.
inline constexpr double kMinCanonicalScalePx = 1e-6;

// One frame's root and scale in pixels:
//   root  = mean of the layout's root_keypoints that are present;
//   scale = RMS distance of all present keypoints from the root.
// The RMS keeps translation invariance and scales exactly with a uniform
// zoom; it shifts a little when limbs go missing, which the caller accepts
// in exchange for needing no per-layout bone lengths. Returns false (outputs
// untouched) when no root keypoint is present, fewer than 2 keypoints are
// present, or the scale is degenerate.
bool RootAndScale(const Keypoint2D* frame, const KeypointLayout& layout,
                  Eigen::Vector2d* root, double* scale);

// Per-frame roots and scales of a clip with gaps filled: forward from the
// previous usable frame, and backward from the first usable one for a
// leading gap. Throws InputError (naming `source`) when no frame is usable.
void FrameRootsAndScales(const Clip2D& clip, const std::string& source,
                         std::vector<Eigen::Vector2d>* roots,
                         std::vector<double>* scales);

// X^can: frame t holds local_pose_t, delta_root[t] = (root_t − root_{t−1})
// / s_t and delta_log_scale[t] = log(s_t / s_{t−1}); both are 0 at t = 0,
// whose root and scale are stored absolutely.
struct CanonicalClip {
  const KeypointLayout* layout = &Coco17Layout();
  double fps = 30.0;
  KeypointTrack local_pose;  // x̄; confidences kept, missing stay missing
  std::vector<Eigen::Vector2d> delta_root;
  std::vector<double> delta_log_scale;
  Eigen::Vector2d first_root_px = Eigen::Vector2d::Zero();
  double first_scale_px = 1.0;
  int image_width_px = 1920;
  int image_height_px = 1080;

  int num_frames() const { return local_pose.num_frames(); }
};

// G(X). A frame without its own root/scale (see RootAndScale) carries the
// previous frame's (frames before the first usable one take that frame's).
// Object tracks are not part of the representation. Throws InputError
// (naming `source`) when no frame has a root and scale.
CanonicalClip ToCanonical(const Clip2D& clip, const std::string& source = "");

// G⁻¹(X^can): the exact inverse of ToCanonical for the keypoints (up to
// floating-point rounding). Throws InputError on inconsistent sizes or a
// non-positive first scale.
Clip2D FromCanonical(const CanonicalClip& canonical);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_CANONICAL_H_
