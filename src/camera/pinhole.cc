#include "camera/pinhole.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "common/error.h"

namespace m2d {

PinholeCamera::PinholeCamera(const Intrinsics& intrinsics,
                             const Eigen::Matrix3d& rotation_world_to_camera,
                             const Eigen::Vector3d& translation_m)
    : intrinsics_(intrinsics),
      rotation_(rotation_world_to_camera),
      translation_m_(translation_m) {}

PinholeCamera PinholeCamera::LookAt(const Intrinsics& intrinsics,
                                    const Eigen::Vector3d& eye_m,
                                    const Eigen::Vector3d& target_m,
                                    const Eigen::Vector3d& up) {
  // Camera axes in world coordinates: z along the view, x = z × up (right),
  // y = z × x (down in the image).
  Eigen::Vector3d forward = target_m - eye_m;
  if (forward.norm() < 1e-9) throw ConfigError("LookAt: eye equals target");
  forward.normalize();
  Eigen::Vector3d right = forward.cross(up);
  if (right.norm() < 1e-9) {
    throw ConfigError("LookAt: view direction is parallel to the up vector");
  }
  right.normalize();
  Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;
  rotation.row(0) = right;
  rotation.row(1) = down;
  rotation.row(2) = forward;
  return PinholeCamera(intrinsics, rotation, -rotation * eye_m);
}

Projection PinholeCamera::Project(const Eigen::Vector3d& point_world_m) const {
  Projection out;
  Eigen::Vector3d p = ToCamera(point_world_m);
  out.depth_m = p.z();
  out.in_front = p.z() >= kMinProjectDepth_m;
  if (!out.in_front) {
    out.pixel_px.setConstant(std::numeric_limits<double>::quiet_NaN());
    return out;
  }
  out.pixel_px.x() = intrinsics_.fx_px * p.x() / p.z() + intrinsics_.cx_px;
  out.pixel_px.y() = intrinsics_.fy_px * p.y() / p.z() + intrinsics_.cy_px;
  return out;
}

Eigen::Matrix<double, 2, 3> PinholeCamera::ProjectJacobian(
    const Eigen::Vector3d& point_world_m) const {
  // pixel = f * (x/z, y/z) + c with p = R X + t, so
  // d pixel / d X = [fx/z, 0, -fx x/z²; 0, fy/z, -fy y/z²] · R.
  Eigen::Vector3d p = ToCamera(point_world_m);
  Eigen::Matrix<double, 2, 3> d_pixel_d_camera =
      Eigen::Matrix<double, 2, 3>::Zero();
  if (p.z() < kMinProjectDepth_m) return d_pixel_d_camera;
  double inv_z = 1.0 / p.z();
  d_pixel_d_camera(0, 0) = intrinsics_.fx_px * inv_z;
  d_pixel_d_camera(0, 2) = -intrinsics_.fx_px * p.x() * inv_z * inv_z;
  d_pixel_d_camera(1, 1) = intrinsics_.fy_px * inv_z;
  d_pixel_d_camera(1, 2) = -intrinsics_.fy_px * p.y() * inv_z * inv_z;
  return d_pixel_d_camera * rotation_;
}

Eigen::Vector3d PinholeCamera::RayDirectionWorld(
    const Eigen::Vector2d& pixel_px) const {
  const Eigen::Vector3d direction_camera(
      (pixel_px.x() - intrinsics_.cx_px) / intrinsics_.fx_px,
      (pixel_px.y() - intrinsics_.cy_px) / intrinsics_.fy_px, 1.0);
  return rotation_.transpose() * direction_camera;
}

PinholeCamera PinholeCamera::Translated(const Eigen::Vector3d& offset_m) const {
  // Centre c' = c + offset, so t' = -R c' = t - R offset.
  return PinholeCamera(intrinsics_, rotation_,
                       translation_m_ - rotation_ * offset_m);
}

}  // namespace m2d
