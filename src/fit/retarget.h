// fit: the character's joint angles from 3D keypoints of another skeleton
// (motion capture of other people, e.g. the CMU captures of
// assimp-testmodels), by a per-frame 3D keypoint fit with Ceres. It widens
// what the pose prior (fit/pose_prior.h) is learned from beyond motions
// recorded on the character's own skeleton.
#ifndef MIMIC2D_FIT_RETARGET_H_
#define MIMIC2D_FIT_RETARGET_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace m2d {

class Character;

struct RetargetOptions {
  // Per-keypoint weight of the face points (eyes, ears, nose), which a
  // motion-capture map only approximates; body joints weigh 1.
  double face_weight = 0.3;
  // Pull toward the rest pose (per rad): hinges the 17 points do not
  // determine (ankles, the neck's twist) stay near rest.
  double rest_weight = 0.005;
  // Pull toward the previous frame's angles (per rad): of two equally good
  // solutions a frame keeps its neighbour's.
  double continuity_weight = 0.01;
  int max_iterations = 50;
};

struct RetargetSummary {
  int num_frames = 0;
  double scale = 1.0;         // applied to the source keypoints
  double mean_error_m = 0.0;  // body keypoints, after scaling
  double worst_frame_error_m = 0.0;
  // Per frame, over the body keypoints (the face's are approximate): the
  // mean and the largest distance of a placed keypoint to its target (m).
  std::vector<double> frame_mean_error_m;
  std::vector<double> frame_worst_error_m;
};

// Hinge angles (rad, action order, within their ranges) per frame that
// place the character's COCO-17 keypoints on `keypoints_m` (per frame, in
// layout order, metres, z up), scaled first by the ratio of the
// character's limb lengths to the source's (median over frames). Each frame
// starts from the previous frame's solution, or from `starts_rad` (per
// frame, action order, clamped into the ranges) when given. InputError
// naming `source` for a frame without 17 finite points or starts of the
// wrong shape.
std::vector<Eigen::VectorXd> RetargetKeypointsToHinges(
    const Character& character,
    const std::vector<std::vector<Eigen::Vector3d>>& keypoints_m,
    const RetargetOptions& options, const std::string& source,
    RetargetSummary* summary = nullptr,
    const std::vector<Eigen::VectorXd>* starts_rad = nullptr);

}  // namespace m2d

#endif  // MIMIC2D_FIT_RETARGET_H_
