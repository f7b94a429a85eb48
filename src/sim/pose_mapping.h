// sim: MuJoCo physics for characters — models, simulations, PD control,
// pose mapping, keypoints and contacts.
#ifndef MIMIC2D_SIM_POSE_MAPPING_H_
#define MIMIC2D_SIM_POSE_MAPPING_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "motion/motion3d.h"
#include "sim/character.h"

namespace m2d {

// Angles (a, b, c) with R = Rx(a) Ry(b) Rz(c) (intrinsic x-y-z), the
// principal solution: b in [-pi/2, pi/2], a and c in (-pi, pi].
Eigen::Vector3d IntrinsicXyzAngles(const Eigen::Quaterniond& rotation);
// The other solution (a + pi, pi - b, c + pi), wrapped to (-pi, pi].
Eigen::Vector3d AlternateXyzAngles(const Eigen::Vector3d& angles);
Eigen::Quaterniond FromIntrinsicXyzAngles(const Eigen::Vector3d& angles);

// Writes `pose` into the character's entries of `qpos` (size model->nq):
// root position and quaternion (w, x, y, z), hinge angles. Spherical joints
// take whichever of the two Euler solutions fits the hinge ranges better.
// Other entries (e.g. a ball's) are left untouched.
void PoseToQpos(const Character& character, const Pose3D& pose, double* qpos);

// `poses` (a clip) as qpos rows, each ball joint's angles continuing the
// previous frame's: the first frame as PoseToQpos, then each joint's Euler
// solution nearest (angle by angle, modulo 2 pi) the one before it. Chosen
// frame by frame, PoseToQpos switches between the two solutions where
// their fit to the ranges crosses over, a jump of about pi in three angles
// that no motion makes (11 such steps in the DeepMimic kick; docs/fit.md,
// "Euler switches in the truth"). Continuity comes first: an angle that
// turns past +-pi keeps going instead of wrapping.
std::vector<std::vector<double>> PosesToQposAlongClip(
    const Character& character, const std::vector<Pose3D>& poses);

// The character's pose in `qpos` (fixed joints get identity rotations).
Pose3D QposToPose(const Character& character, const double* qpos);

// Writes the character's entries of `qvel` (size model->nv) for moving from
// `from` to `to` in `dt_s` by finite differences: root linear velocity
// (world frame) and angular velocity (root frame, as MuJoCo's freejoint
// expects), and hinge rates. Euler angles of `to` are taken on the branch
// nearest those of `from`, so the rates stay continuous (and the hinges,
// integrated, reach `to` exactly). With `at` (the pose the velocity is set
// with, e.g. the middle of a central difference), a ball joint's rates are
// instead those of the Euler solution PoseToQpos picks for `at` that turn it
// at the angular velocity from `from` to `to`: right whichever solution
// `from` and `to` would pick, and not thrown off near gimbal lock.
void QvelFromPoses(const Character& character, const Pose3D& from,
                   const Pose3D& to, double dt_s, double* qvel,
                   const Pose3D* at = nullptr);

}  // namespace m2d

#endif  // MIMIC2D_SIM_POSE_MAPPING_H_
