#include "sim/pose_mapping.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

double WrapAngle(double angle) {
  angle = std::remainder(angle, 2.0 * M_PI);
  return angle <= -M_PI ? angle + 2.0 * M_PI : angle;
}

// How badly three hinge angles fit their ranges: total distance outside the
// ranges, then (to break ties) normalized distance from the range centres.
std::pair<double, double> RangeMisfit(const Character& character,
                                      int first_hinge,
                                      const Eigen::Vector3d& angles) {
  double outside = 0.0;
  double from_centre = 0.0;
  for (int k = 0; k < 3; ++k) {
    const ActuatedHinge& hinge = character.hinges()[first_hinge + k];
    outside += std::max(0.0, hinge.range_low_rad - angles[k]) +
               std::max(0.0, angles[k] - hinge.range_high_rad);
    const double half = 0.5 * (hinge.range_high_rad - hinge.range_low_rad);
    from_centre +=
        std::abs(angles[k] - hinge.target_mid_rad) / std::max(half, 1e-9);
  }
  return {outside, from_centre};
}

Eigen::Vector3d SphericalAngles(const Character& character, int first_hinge,
                                const Eigen::Quaterniond& rotation) {
  const Eigen::Vector3d principal = IntrinsicXyzAngles(rotation);
  const Eigen::Vector3d alternate = AlternateXyzAngles(principal);
  return RangeMisfit(character, first_hinge, alternate) <
                 RangeMisfit(character, first_hinge, principal)
             ? alternate
             : principal;
}

// The solution for `rotation` nearest to `reference` (angle by angle,
// modulo 2 pi), so that differences between frames stay small.
Eigen::Vector3d NearestXyzAngles(const Eigen::Quaterniond& rotation,
                                 const Eigen::Vector3d& reference) {
  const Eigen::Vector3d principal = IntrinsicXyzAngles(rotation);
  Eigen::Vector3d best;
  double best_distance = INFINITY;
  for (const Eigen::Vector3d& candidate :
       {principal, AlternateXyzAngles(principal)}) {
    Eigen::Vector3d unwrapped;
    for (int k = 0; k < 3; ++k) {
      unwrapped[k] = reference[k] + WrapAngle(candidate[k] - reference[k]);
    }
    const double distance = (unwrapped - reference).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best = unwrapped;
    }
  }
  return best;
}

// The constant angular velocity that makes the turn `delta` in `dt_s`, the
// short way round: its rotation vector divided by the time.
Eigen::Vector3d AngularVelocityOfTurn(Eigen::Quaterniond delta, double dt_s) {
  if (delta.w() < 0) delta.coeffs() *= -1.0;
  const Eigen::AngleAxisd turn(delta);
  return turn.axis() * (turn.angle() / dt_s);
}

// The angular velocity (in the parent's axes) that turns `from` into `to`
// in `dt_s`: to = exp(dt [w]x) from.
Eigen::Vector3d ParentAxesAngularVelocity(const Eigen::Quaterniond& from,
                                          const Eigen::Quaterniond& to,
                                          double dt_s) {
  return AngularVelocityOfTurn(to.normalized() * from.normalized().conjugate(),
                               dt_s);
}

// The rates of intrinsic XYZ angles (a, b, c) that turn at `omega` (parent
// axes): omega = J rates, J's columns x, Rx(a) y, Rx(a) Ry(b) z. det J =
// cos b: near gimbal lock the rates of a and c alone are undefined, and a
// small damping keeps them finite (at most ~1/(2 * 0.01) x |omega|).
Eigen::Vector3d XyzRatesFor(const Eigen::Vector3d& angles,
                            const Eigen::Vector3d& omega) {
  const Eigen::AngleAxisd about_x(angles[0], Eigen::Vector3d::UnitX());
  Eigen::Matrix3d jacobian;
  jacobian.col(0) = Eigen::Vector3d::UnitX();
  jacobian.col(1) = about_x * Eigen::Vector3d::UnitY();
  jacobian.col(2) =
      about_x * (Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
                 Eigen::Vector3d::UnitZ());
  constexpr double kDamping2 = 1e-4;  // 0.01^2
  const Eigen::Matrix3d normal =
      jacobian.transpose() * jacobian + kDamping2 * Eigen::Matrix3d::Identity();
  return normal.ldlt().solve(jacobian.transpose() * omega);
}

// Signed angle of a rotation about a unit axis (its twist), in (-pi, pi].
double AngleAbout(const Eigen::Quaterniond& rotation,
                  const Eigen::Vector3d& axis) {
  return WrapAngle(2.0 * std::atan2(rotation.vec().dot(axis), rotation.w()));
}

void CheckPoseSize(const Character& character, const Pose3D& pose) {
  if (static_cast<int>(pose.local_rotations.size()) !=
      character.skeleton().num_joints()) {
    throw InputError(
        "", "pose has " + std::to_string(pose.local_rotations.size()) +
                " joint rotations; skeleton " + character.skeleton().name +
                " has " + std::to_string(character.skeleton().num_joints()));
  }
}

}  // namespace

Eigen::Vector3d IntrinsicXyzAngles(const Eigen::Quaterniond& rotation) {
  // R = Rx(a) Ry(b) Rz(c) has R02 = sin b, R12 = -sin a cos b,
  // R22 = cos a cos b, R01 = -cos b sin c, R00 = cos b cos c.
  const Eigen::Matrix3d r = rotation.normalized().toRotationMatrix();
  const double b = std::asin(std::clamp(r(0, 2), -1.0, 1.0));
  if (std::abs(r(0, 2)) > 1.0 - 1e-12) {
    // Gimbal lock: only a +- c is defined; put it all in a.
    const double a = std::atan2(r(2, 1), r(1, 1));
    return Eigen::Vector3d(a, b, 0.0);
  }
  return Eigen::Vector3d(std::atan2(-r(1, 2), r(2, 2)), b,
                         std::atan2(-r(0, 1), r(0, 0)));
}

Eigen::Vector3d AlternateXyzAngles(const Eigen::Vector3d& angles) {
  return Eigen::Vector3d(WrapAngle(angles[0] + M_PI),
                         WrapAngle(M_PI - angles[1]),
                         WrapAngle(angles[2] + M_PI));
}

Eigen::Quaterniond FromIntrinsicXyzAngles(const Eigen::Vector3d& angles) {
  return Eigen::AngleAxisd(angles[0], Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(angles[2], Eigen::Vector3d::UnitZ());
}

void PoseToQpos(const Character& character, const Pose3D& pose, double* qpos) {
  CheckPoseSize(character, pose);
  const Skeleton& skeleton = character.skeleton();
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const BoundJoint& bound = character.joints()[j];
    const Eigen::Quaterniond& rotation = pose.local_rotations[j];
    if (bound.type == JointType::kFree) {
      double* root = qpos + character.root_qpos_address();
      const Eigen::Quaterniond q = rotation.normalized();
      root[0] = pose.root_position_m.x();
      root[1] = pose.root_position_m.y();
      root[2] = pose.root_position_m.z();
      root[3] = q.w();
      root[4] = q.x();
      root[5] = q.y();
      root[6] = q.z();
    } else if (bound.type == JointType::kSpherical) {
      const Eigen::Vector3d angles =
          SphericalAngles(character, bound.first_hinge, rotation);
      for (int k = 0; k < 3; ++k) {
        qpos[character.hinges()[bound.first_hinge + k].qpos_address] =
            angles[k];
      }
    } else if (bound.type == JointType::kRevolute) {
      qpos[character.hinges()[bound.first_hinge].qpos_address] =
          bound.revolute_sign * AngleAbout(rotation, skeleton.joints[j].axis);
    }
  }
}

std::vector<std::vector<double>> PosesToQposAlongClip(
    const Character& character, const std::vector<Pose3D>& poses) {
  const int nq = character.model()->nq;
  std::vector<std::vector<double>> rows(poses.size(),
                                        std::vector<double>(nq, 0.0));
  for (size_t t = 0; t < poses.size(); ++t) {
    PoseToQpos(character, poses[t], rows[t].data());
    if (t == 0) continue;
    for (int j = 0; j < character.skeleton().num_joints(); ++j) {
      const BoundJoint& bound = character.joints()[j];
      if (bound.type != JointType::kSpherical) continue;
      int address[3];
      Eigen::Vector3d before;
      for (int k = 0; k < 3; ++k) {
        address[k] = character.hinges()[bound.first_hinge + k].qpos_address;
        before[k] = rows[t - 1][address[k]];
      }
      const Eigen::Vector3d nearest =
          NearestXyzAngles(poses[t].local_rotations[j], before);
      for (int k = 0; k < 3; ++k) rows[t][address[k]] = nearest[k];
    }
  }
  return rows;
}

Pose3D QposToPose(const Character& character, const double* qpos) {
  const Skeleton& skeleton = character.skeleton();
  Pose3D pose;
  pose.local_rotations.assign(skeleton.num_joints(),
                              Eigen::Quaterniond::Identity());
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const BoundJoint& bound = character.joints()[j];
    if (bound.type == JointType::kFree) {
      const double* root = qpos + character.root_qpos_address();
      pose.root_position_m = Eigen::Vector3d(root[0], root[1], root[2]);
      pose.local_rotations[j] =
          Eigen::Quaterniond(root[3], root[4], root[5], root[6]).normalized();
    } else if (bound.type == JointType::kSpherical) {
      Eigen::Vector3d angles;
      for (int k = 0; k < 3; ++k) {
        angles[k] =
            qpos[character.hinges()[bound.first_hinge + k].qpos_address];
      }
      pose.local_rotations[j] = FromIntrinsicXyzAngles(angles);
    } else if (bound.type == JointType::kRevolute) {
      const double angle =
          qpos[character.hinges()[bound.first_hinge].qpos_address];
      pose.local_rotations[j] = Eigen::Quaterniond(Eigen::AngleAxisd(
          bound.revolute_sign * angle, skeleton.joints[j].axis));
    }
  }
  return pose;
}

void QvelFromPoses(const Character& character, const Pose3D& from,
                   const Pose3D& to, double dt_s, double* qvel,
                   const Pose3D* at) {
  CheckPoseSize(character, from);
  CheckPoseSize(character, to);
  if (at) CheckPoseSize(character, *at);
  if (!(dt_s > 0.0)) throw InputError("", "QvelFromPoses needs dt_s > 0");
  const Skeleton& skeleton = character.skeleton();
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const BoundJoint& bound = character.joints()[j];
    if (bound.type == JointType::kFree) {
      double* root = qvel + character.root_dof_address();
      const Eigen::Vector3d linear =
          (to.root_position_m - from.root_position_m) / dt_s;
      // Body-frame angular velocity: q_to = q_from * exp(omega dt / 2).
      const Eigen::Vector3d angular = AngularVelocityOfTurn(
          from.local_rotations[j].normalized().conjugate() *
              to.local_rotations[j].normalized(),
          dt_s);
      for (int k = 0; k < 3; ++k) {
        root[k] = linear[k];
        root[3 + k] = angular[k];
      }
    } else if (bound.type == JointType::kSpherical) {
      Eigen::Vector3d rates;
      if (at) {
        const Eigen::Vector3d angles = SphericalAngles(
            character, bound.first_hinge, at->local_rotations[j]);
        rates = XyzRatesFor(
            angles, ParentAxesAngularVelocity(from.local_rotations[j],
                                              to.local_rotations[j], dt_s));
      } else {
        const Eigen::Vector3d start = SphericalAngles(
            character, bound.first_hinge, from.local_rotations[j]);
        rates = (NearestXyzAngles(to.local_rotations[j], start) - start) / dt_s;
      }
      for (int k = 0; k < 3; ++k) {
        qvel[character.hinges()[bound.first_hinge + k].dof_address] = rates[k];
      }
    } else if (bound.type == JointType::kRevolute) {
      const Eigen::Vector3d& axis = skeleton.joints[j].axis;
      const double change =
          WrapAngle(AngleAbout(to.local_rotations[j], axis) -
                    AngleAbout(from.local_rotations[j], axis));
      qvel[character.hinges()[bound.first_hinge].dof_address] =
          bound.revolute_sign * change / dt_s;
    }
  }
}

}  // namespace m2d
