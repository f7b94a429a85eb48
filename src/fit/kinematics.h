// fit: estimating cameras and 3D poses from 2D keypoints alone (an
// SMPLify-like fit with Ceres), the first stage of learning from video.
//
// This header: the character's forward kinematics, written once as templated
// code so that Ceres' Jets flow through it. The pose is parameterized exactly
// as MuJoCo's qpos is (root position, root quaternion, hinge angles), so
// joint limits are the MJCF hinge ranges and a fitted pose maps onto the
// simulated character without conversion.
#ifndef MIMIC2D_FIT_KINEMATICS_H_
#define MIMIC2D_FIT_KINEMATICS_H_

#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "motion/motion3d.h"
#include "motion/skeleton.h"

namespace m2d {

class Character;

// A point fixed in one joint's frame (a keypoint or a sole corner).
struct BodyPoint {
  int joint = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
};

// A sphere fixed in one joint's frame: the fit's stand-in for the
// character's collision geoms (a capsule or a box is a row of them), as
// SMPLify stands spheres in for its capsules.
struct CollisionSphere {
  BodyPoint centre;
  double radius_m = 0.0;
  int geom = -1;  // the MuJoCo geom it stands in for
};

// The character's kinematic tree as plain data, read once from a Character.
struct KinematicModel {
  struct Joint {
    int parent = -1;
    JointType type = JointType::kFixed;
    Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  // in parent frame
    Eigen::Vector3d axis = Eigen::Vector3d::UnitY();     // revolute only
    int first_hinge = -1;        // index into the hinge angles; -1: none
    double revolute_sign = 1.0;  // MJCF angle = sign x angle about axis

    // Hinge angles this joint owns: 3 for a ball, 1 for a hinge.
    int num_hinges() const {
      return type == JointType::kSpherical  ? 3
             : type == JointType::kRevolute ? 1
                                            : 0;
    }
  };
  std::string skeleton_name;
  std::vector<Joint> joints;           // parents precede children
  std::vector<BodyPoint> keypoints;    // in keypoint-layout order
  std::vector<BodyPoint> sole_points;  // contact bodies' lowest box corners
  std::vector<int> sole_foot;          // per sole point: 0 or 1, which foot
  std::vector<BodyPoint> mass_points;  // each body's centre of mass
  std::vector<double> mass_fractions;  // per mass point: its share, sum 1
  int num_feet = 0;
  std::vector<double> hinge_low_rad;  // MJCF ranges, in action order
  std::vector<double> hinge_high_rad;
  double standing_root_height_m = 0.0;  // root z with soles on the floor
  std::vector<CollisionSphere> collision_spheres;
  // Pairs of collision spheres (indices, first < second) that the
  // simulation lets collide (different bodies, not parent and child, not
  // excluded, contype and conaffinity matching) and that are apart in the
  // rest pose: the pairs a fitted pose must not push through each other.
  std::vector<std::pair<int, int>> collision_pairs;

  int num_hinges() const { return static_cast<int>(hinge_low_rad.size()); }
  int num_keypoints() const { return static_cast<int>(keypoints.size()); }
  int num_sole_points() const { return static_cast<int>(sole_points.size()); }

  // Reads the skeleton, keypoint sites, hinge ranges and the sole corners of
  // the ground-contact bodies' boxes from a loaded character.
  static KinematicModel FromCharacter(const Character& character);
};

// Parameters of one frame's pose, MuJoCo's layout: root position (3), root
// quaternion (w, x, y, z; any norm, normalized here), hinge angles.
inline constexpr int kRootPositionSize = 3;
inline constexpr int kRootQuaternionSize = 4;

namespace fk_internal {

template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Vector3 = Eigen::Matrix<T, 3, 1>;

// Rotation by `angle` about the unit axis `axis` (Rodrigues; K and K^2
// are constants, so only two scalars carry derivatives).
template <typename T>
Matrix3<T> AxisRotation(const Eigen::Vector3d& axis, const T& angle) {
  using std::cos;
  using std::sin;
  Eigen::Matrix3d k;
  k << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  const Eigen::Matrix3d k2 = k * k;
  const T s = sin(angle), one_minus_c = T(1) - cos(angle);
  Matrix3<T> rotation;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      rotation(r, c) =
          T(r == c ? 1.0 : 0.0) + s * k(r, c) + one_minus_c * k2(r, c);
  return rotation;
}

// Rx(a) Ry(b) Rz(c) in closed form (MuJoCo's x, y, z hinge chain).
template <typename T>
Matrix3<T> IntrinsicXyzRotation(const T* angles) {
  using std::cos;
  using std::sin;
  const T ca = cos(angles[0]), sa = sin(angles[0]);
  const T cb = cos(angles[1]), sb = sin(angles[1]);
  const T cc = cos(angles[2]), sc = sin(angles[2]);
  Matrix3<T> rotation;
  rotation(0, 0) = cb * cc;
  rotation(0, 1) = -cb * sc;
  rotation(0, 2) = sb;
  rotation(1, 0) = ca * sc + sa * sb * cc;
  rotation(1, 1) = ca * cc - sa * sb * sc;
  rotation(1, 2) = -sa * cb;
  rotation(2, 0) = sa * sc - ca * sb * cc;
  rotation(2, 1) = sa * cc + ca * sb * sc;
  rotation(2, 2) = ca * cb;
  return rotation;
}

}  // namespace fk_internal

inline constexpr int kMaxFitJoints = 64;   // FromCharacter checks the count
inline constexpr int kMaxFitPoints = 128;  // keypoints + sole points, checked

namespace fk_internal {

// A joint's rotation relative to its parent's frame.
template <typename T>
Matrix3<T> LocalRotation(const KinematicModel::Joint& joint,
                         const T* root_quaternion_wxyz, const T* hinges_rad) {
  Matrix3<T> local = Matrix3<T>::Identity();
  if (joint.type == JointType::kFree) {
    T rotation_row_major[9];
    ceres::QuaternionToRotation(root_quaternion_wxyz, rotation_row_major);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) local(r, c) = rotation_row_major[3 * r + c];
  } else if (joint.type == JointType::kSpherical) {
    local = IntrinsicXyzRotation(hinges_rad + joint.first_hinge);
  } else if (joint.type == JointType::kRevolute) {
    local = AxisRotation<T>(
        joint.axis, T(joint.revolute_sign) * hinges_rad[joint.first_hinge]);
  }
  return local;
}

}  // namespace fk_internal

// Every joint's world frame (orientation and origin), parents before
// children: the forward kinematics that CharacterPoints and
// CharacterPointsWithJacobian share.
template <typename T>
void JointFrames(const KinematicModel& model, const T* root_position_m,
                 const T* root_quaternion_wxyz, const T* hinges_rad,
                 fk_internal::Matrix3<T>* orientation,
                 fk_internal::Vector3<T>* position) {
  using Vector3 = fk_internal::Vector3<T>;
  const int num_joints = static_cast<int>(model.joints.size());
  for (int j = 0; j < num_joints; ++j) {
    const KinematicModel::Joint& joint = model.joints[j];
    const fk_internal::Matrix3<T> local =
        fk_internal::LocalRotation(joint, root_quaternion_wxyz, hinges_rad);
    const Vector3 offset = joint.offset_m.cast<T>();
    if (joint.parent < 0) {
      position[j] =
          Vector3(root_position_m[0], root_position_m[1], root_position_m[2]) +
          offset;
      orientation[j] = local;
    } else {
      position[j] = position[joint.parent] + orientation[joint.parent] * offset;
      orientation[j] = orientation[joint.parent] * local;
    }
  }
}

// Per joint: 1 when one of `hinges` (indices into a frame's hinge angles)
// turns it, its own or an ancestor's; parents precede children.
std::vector<char> JointsMovedBy(const KinematicModel& model,
                                const std::vector<int>& hinges);

// JointFrames for the joints flagged in `moves` alone (none of them the
// root), the others' frames given in doubles (`fixed_orientation`,
// `fixed_position`, as JointFrames computed them): a limb's frames when
// only its hinges vary, without carrying the rest of the body in Jets.
template <typename T>
void MovedJointFrames(const KinematicModel& model,
                      const std::vector<char>& moves,
                      const Eigen::Matrix3d* fixed_orientation,
                      const Eigen::Vector3d* fixed_position,
                      const T* hinges_rad, fk_internal::Matrix3<T>* orientation,
                      fk_internal::Vector3<T>* position) {
  const int num_joints = static_cast<int>(model.joints.size());
  for (int j = 0; j < num_joints; ++j) {
    if (!moves[j]) continue;
    const KinematicModel::Joint& joint = model.joints[j];
    const fk_internal::Matrix3<T> local =
        fk_internal::LocalRotation<T>(joint, nullptr, hinges_rad);
    const int parent = joint.parent;
    const fk_internal::Matrix3<T> parent_orientation =
        moves[parent] ? orientation[parent]
                      : fk_internal::Matrix3<T>(
                            fixed_orientation[parent].template cast<T>());
    const fk_internal::Vector3<T> parent_position =
        moves[parent] ? position[parent]
                      : fk_internal::Vector3<T>(
                            fixed_position[parent].template cast<T>());
    position[j] =
        parent_position + parent_orientation * joint.offset_m.cast<T>();
    orientation[j] = parent_orientation * local;
  }
}

// World positions of the model's keypoints then its sole points, 3 numbers
// each, into `points_m` (size 3 x (keypoints + sole points)).
template <typename T>
void CharacterPoints(const KinematicModel& model, const T* root_position_m,
                     const T* root_quaternion_wxyz, const T* hinges_rad,
                     T* points_m) {
  using Vector3 = fk_internal::Vector3<T>;
  // Outline: compose each joint's world frame from its parent's, then place
  // the body points in their joints' frames.
  fk_internal::Matrix3<T> orientation[kMaxFitJoints];
  Vector3 position[kMaxFitJoints];
  JointFrames(model, root_position_m, root_quaternion_wxyz, hinges_rad,
              orientation, position);
  int out = 0;
  for (const std::vector<BodyPoint>* points :
       {&model.keypoints, &model.sole_points}) {
    for (const BodyPoint& point : *points) {
      const Vector3 world = position[point.joint] +
                            orientation[point.joint] * point.offset_m.cast<T>();
      for (int k = 0; k < 3; ++k) points_m[out++] = world[k];
    }
  }
}

// Columns of a pose Jacobian: root position (3), root quaternion (4, as
// given: CharacterPoints normalizes it), hinge angles.
inline int PoseJacobianColumns(const KinematicModel& model) {
  return kRootPositionSize + kRootQuaternionSize + model.num_hinges();
}

// CharacterPoints in doubles, with the points' derivatives with respect to
// the pose in `jacobian` (row-major: 3 x points rows, PoseJacobianColumns
// columns). Analytic: a hinge moves a point by its world axis x the lever
// arm from its joint; the quaternion's columns are dR/dq applied to the
// point in the root frame. The fit's per-frame costs use it instead of
// automatic differentiation, which spent most of a fit's time pushing
// 16-wide Jets through these same products (docs/fit.md, "Speed").
void CharacterPointsWithJacobian(const KinematicModel& model,
                                 const double* root_position_m,
                                 const double* root_quaternion_wxyz,
                                 const double* hinges_rad, double* points_m,
                                 double* jacobian);

// World positions of `points` (3 numbers each) into `points_m` and, when
// `jacobian` is not null, their derivatives with respect to the pose
// (row-major: 3 x points rows, PoseJacobianColumns columns), as
// CharacterPointsWithJacobian computes them.
void BodyPointsWithJacobian(const KinematicModel& model,
                            const double* root_position_m,
                            const double* root_quaternion_wxyz,
                            const double* hinges_rad,
                            const std::vector<BodyPoint>& points,
                            double* points_m, double* jacobian);

// The world centres of `model`'s collision spheres for one pose, 3 numbers
// each in collision_spheres order.
std::vector<double> CollisionSphereCentres(const KinematicModel& model,
                                           const double* root_position_m,
                                           const double* root_quaternion_wxyz,
                                           const double* hinges_rad);

// The gap between the surfaces of collision spheres `a` and `b` (m;
// negative where they overlap), their centres as CollisionSphereCentres
// gives them.
double SphereGapM(const KinematicModel& model,
                  const std::vector<double>& centres_m, int a, int b);

// The whole body's centre of mass (world, m) into `com_m` (3), with its
// derivatives with respect to the pose in `jacobian` (row-major 3 x
// PoseJacobianColumns; null: none): the mass-weighted mean of the bodies'
// centres.
void CenterOfMassWithJacobian(const KinematicModel& model,
                              const double* root_position_m,
                              const double* root_quaternion_wxyz,
                              const double* hinges_rad, double* com_m,
                              double* jacobian);

// A limb: a chain of joints hanging off the trunk (an arm, a leg, the
// head), the hinges that move its keypoints, and those keypoints. Its
// keypoints depend on its own hinges alone once the trunk is placed, so each
// limb's pose can be searched on its own.
struct Limb {
  std::vector<int> hinges;     // indices into a frame's hinge angles
  std::vector<int> keypoints;  // layout indices
  std::vector<std::vector<double>> starts;  // limb hinge values per start
};

// The limbs of `model`: subtrees that are plain chains (no joint in them
// has two children) under a joint that branches, with at least one
// keypoint moved by their hinges. Starts: a grid over the ranges of the
// limb's first kLimbGridJoints moving joints (a ball joint's first two
// axes, twist at rest; a hinge at rest and toward its wider side), so that
// a limb raised forward, backward or out is near one of them; joints
// further out start at rest.
constexpr int kLimbGridJoints = 2;
std::vector<Limb> FindLimbs(const KinematicModel& model);

// A fitted frame as the skeleton's Pose3D (the mapping the simulation uses,
// sim/pose_mapping.h's QposToPose, so the two cannot disagree).
Pose3D FittedPose(const Character& character, const double* root_position_m,
                  const double* root_quaternion_wxyz, const double* hinges_rad);

}  // namespace m2d

#endif  // MIMIC2D_FIT_KINEMATICS_H_
