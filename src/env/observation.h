// env: observations as pure functions of the simulated state and the 2D
// reference. Nothing the policy reads sees a camera: 2D inputs are expressed
// relative to the reference's own root and scale in the image, so two
// cameras that produce the same image produce the same observation. The one
// exception is the optional critic-only block (asymmetric actor-critic),
// which only the value function reads, in training.
#ifndef MIMIC2D_ENV_OBSERVATION_H_
#define MIMIC2D_ENV_OBSERVATION_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "motion/clip2d.h"

namespace m2d {

// Sizes of the observation's parts, in the order they are laid out:
// [proprioception | object state | critic-only | 2D block]. The 2D block is
// what the encoder phi reads per view; proprioception and object state join
// after phi for the policy and the critic; the critic-only block (empty
// unless env.critic_observes_3d) joins for the critic alone.
struct ObservationLayout {
  int num_bodies = 0;         // character bodies in proprioception
  int num_objects = 0;        // free objects (e.g. a ball)
  int num_points = 0;         // 2D points per frame: keypoints + objects
  int num_future_frames = 0;  // L reference frames after the current one
  int critic_only_size = 0;   // floats only the critic reads (0: none)

  static constexpr int kBodyFeatures = 3 + 6 + 3 + 3;  // pos, rot6, lin, ang
  static constexpr int kObjectFeatures = 6;            // position, velocity
  static constexpr int kPointFeatures = 3;             // x, y, present

  int proprioception_size() const { return 1 + num_bodies * kBodyFeatures; }
  int object_size() const { return num_objects * kObjectFeatures; }
  // Current projection + L future reference frames.
  int view_size() const {
    return (1 + num_future_frames) * num_points * kPointFeatures;
  }
  // What the policy reads besides phi.
  int actor_base_size() const { return proprioception_size() + object_size(); }
  int view_offset() const { return actor_base_size() + critic_only_size; }
  int size() const { return view_offset() + view_size(); }
};

// World-frame kinematics of the character's bodies; body 0 is the root.
struct BodyKinematics {
  std::vector<Eigen::Vector3d> positions_m;
  std::vector<Eigen::Quaterniond> orientations;
  std::vector<Eigen::Vector3d> linear_velocities_m_s;
  std::vector<Eigen::Vector3d> angular_velocities_rad_s;
};

// Rotation about +z that undoes the root's heading (yaw of its local +x).
Eigen::Quaterniond InverseHeadingRotation(const Eigen::Quaterniond& root);

// Root height, then per body: position relative to the root, orientation as
// the first two columns of its rotation matrix, and linear and angular
// velocity, all in the root's heading frame. Writes
// layout.proprioception_size() floats.
void WriteProprioception(const BodyKinematics& bodies, float* out);

// Per object: position and velocity relative to the root, in the heading
// frame. Writes 6 floats per object.
void WriteObjectState(const BodyKinematics& bodies,
                      const std::vector<Eigen::Vector3d>& object_positions_m,
                      const std::vector<Eigen::Vector3d>& object_velocities_m_s,
                      float* out);

// The image-space frame in which 2D inputs are expressed: a point p maps to
// (p - root_px) / scale_px (the canonical representation's local pose).
struct ImageNormalization {
  Eigen::Vector2d root_px = Eigen::Vector2d::Zero();
  double scale_px = 1.0;
};

// Normalized coordinates are clipped to +-this, so a wild projection cannot
// produce huge inputs.
inline constexpr float kMaxNormalizedCoordinate = 10.0f;

// Writes num_points * 3 floats: normalized (x, y) and a presence flag; a
// missing point (or one behind the camera) is (0, 0, 0).
void WriteNormalizedPoints(const Keypoint2D* points, int num_points,
                           const ImageNormalization& normalization, float* out);

// The 3D-tracking baselines' block in place of a 2D one: writes num_points
// * 3 floats, each point relative to the root `root_m` in the root's heading
// frame (`to_heading`, InverseHeadingRotation), clipped to
// +-kMaxNormalizedCoordinate metres.
void WriteRootRelativePoints(const Eigen::Vector3d* points_m, int num_points,
                             const Eigen::Vector3d& root_m,
                             const Eigen::Quaterniond& to_heading, float* out);

// The critic-only block (asymmetric actor-critic: privileged inputs for the
// value function, which only training uses; the policy never reads them, so
// it stays the paper's and view-invariant). Everything is in the simulated
// root's heading frame, relative to the root:
//  - the 3D reference's keypoints at the current and the next frame (the
//    motion the initial states were filled from: the fit's poses with
//    `initial_states: estimate`), num_keypoints * 3 floats each;
//  - the episode's camera: its centre (m) and its camera-to-world rotation's
//    first two columns (the image's x and y axes), 9 floats.
// Why: the value of a state depends on where the 3D motion goes and on the
// view, which the policy's inputs only imply through the 2D.
inline int CriticOnlySize(int num_keypoints) {
  return 2 * num_keypoints * 3 + 9;
}
void WriteCriticOnlyInputs(const BodyKinematics& bodies,
                           const Eigen::Vector3d* reference_now_m,
                           const Eigen::Vector3d* reference_next_m,
                           int num_keypoints,
                           const Eigen::Vector3d& camera_center_m,
                           const Eigen::Matrix3d& camera_to_world, float* out);

}  // namespace m2d

#endif  // MIMIC2D_ENV_OBSERVATION_H_
