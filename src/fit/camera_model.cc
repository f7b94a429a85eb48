#include "fit/camera_model.h"

namespace m2d {

PinholeCamera ToPinholeCamera(double focal_px, const double* pitch_roll_rad,
                              const double* centre_m, int width_px,
                              int height_px, double yaw_rad) {
  Intrinsics intrinsics;
  intrinsics.fx_px = intrinsics.fy_px = focal_px;
  intrinsics.cx_px = 0.5 * width_px;
  intrinsics.cy_px = 0.5 * height_px;
  intrinsics.width_px = width_px;
  intrinsics.height_px = height_px;
  const Eigen::Matrix3d rotation = FitCameraRotation(pitch_roll_rad, yaw_rad);
  const Eigen::Vector3d centre(centre_m[0], centre_m[1], centre_m[2]);
  return PinholeCamera(intrinsics, rotation, -rotation * centre);
}

Eigen::Vector2d CameraPitchRollRad(const PinholeCamera& camera) {
  // With R = roll * pitch * level: the forward row is (cos p, 0, -sin p) up
  // to a yaw, the right row's z is sin r cos p and the down row's z is
  // -cos r cos p.
  const Eigen::Matrix3d& r = camera.rotation_world_to_camera();
  const double pitch = std::asin(std::clamp(-r(2, 2), -1.0, 1.0));
  const double roll = std::atan2(r(0, 2), -r(1, 2));
  return {pitch, roll};
}

double CameraYawRad(const PinholeCamera& camera) {
  // The forward row is (cos p cos y, cos p sin y, -sin p).
  const Eigen::Matrix3d& r = camera.rotation_world_to_camera();
  return std::atan2(r(2, 1), r(2, 0));
}

}  // namespace m2d
