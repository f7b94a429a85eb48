// fit: the camera the fit estimates. A pinhole with square pixels and the
// principal point at the image centre; orientation = pitch (positive looks
// down) and roll about the optical axis, yaw fixed at 0 (the world heading is
// free, so the camera's yaw defines it: it looks along +x); centre above the
// ground plane z = 0. A rig's other cameras (FitRig) add a yaw: the heading
// they look along, from +x toward +y.
#ifndef MIMIC2D_FIT_CAMERA_MODEL_H_
#define MIMIC2D_FIT_CAMERA_MODEL_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "camera/pinhole.h"

namespace m2d {

// Rows of the world-to-camera rotation at pitch = roll = 0: camera x (right)
// = world -y, camera y (down) = world -z, camera z (forward) = world +x.
template <typename T>
Eigen::Matrix<T, 3, 3> FitCameraRotation(const T* pitch_roll_rad) {
  using std::cos;
  using std::sin;
  const T cp = cos(pitch_roll_rad[0]), sp = sin(pitch_roll_rad[0]);
  const T cr = cos(pitch_roll_rad[1]), sr = sin(pitch_roll_rad[1]);
  Eigen::Matrix<T, 3, 3> level;
  level << T(0), T(-1), T(0), T(0), T(0), T(-1), T(1), T(0), T(0);
  Eigen::Matrix<T, 3, 3> pitch;  // tilt the optical axis toward image-down
  pitch << T(1), T(0), T(0), T(0), cp, -sp, T(0), sp, cp;
  Eigen::Matrix<T, 3, 3> roll;  // about the optical axis
  roll << cr, -sr, T(0), sr, cr, T(0), T(0), T(0), T(1);
  return roll * pitch * level;
}

// The same camera turned by `yaw_rad` about the world's z: it looks along
// (cos yaw, sin yaw) at pitch 0.
template <typename T>
Eigen::Matrix<T, 3, 3> FitCameraRotation(const T* pitch_roll_rad,
                                         const T& yaw_rad) {
  using std::cos;
  using std::sin;
  const T cy = cos(yaw_rad), sy = sin(yaw_rad);
  Eigen::Matrix<T, 3, 3> unturn;  // world to the camera's heading frame
  unturn << cy, sy, T(0), -sy, cy, T(0), T(0), T(0), T(1);
  return FitCameraRotation(pitch_roll_rad) * unturn;
}

// Depth below which a point is treated as this far in front (keeps the
// projection finite while a solver step passes through the camera plane).
inline constexpr double kFitMinDepth_m = 0.05;

// Pixel of `point_m` seen by the camera (focal, pitch/roll, centre) whose
// principal point is (cx_px, cy_px).
template <typename T>
void FitProject(const T& focal_px, const T* pitch_roll_rad, const T* centre_m,
                const T* point_m, double cx_px, double cy_px, T* pixel_px) {
  const Eigen::Matrix<T, 3, 3> rotation = FitCameraRotation(pitch_roll_rad);
  const Eigen::Matrix<T, 3, 1> relative(point_m[0] - centre_m[0],
                                        point_m[1] - centre_m[1],
                                        point_m[2] - centre_m[2]);
  const Eigen::Matrix<T, 3, 1> camera = rotation * relative;
  T depth = camera.z();
  if (depth < T(kFitMinDepth_m)) depth = T(kFitMinDepth_m);
  pixel_px[0] = focal_px * camera.x() / depth + T(cx_px);
  pixel_px[1] = focal_px * camera.y() / depth + T(cy_px);
}

// The same for a camera turned by `yaw_rad` (FitCameraRotation above): the
// point and the centre seen in the camera's heading frame.
template <typename T>
void FitProjectTurned(const T& focal_px, const T* pitch_roll_rad,
                      const T& yaw_rad, const T* centre_m, const T* point_m,
                      double cx_px, double cy_px, T* pixel_px) {
  using std::cos;
  using std::sin;
  const T cy = cos(yaw_rad), sy = sin(yaw_rad);
  const T centre[3] = {cy * centre_m[0] + sy * centre_m[1],
                       -sy * centre_m[0] + cy * centre_m[1], centre_m[2]};
  const T point[3] = {cy * point_m[0] + sy * point_m[1],
                      -sy * point_m[0] + cy * point_m[1], point_m[2]};
  FitProject(focal_px, pitch_roll_rad, centre, point, cx_px, cy_px, pixel_px);
}

// A rigid body (its root's position and orientation) seen by one camera
// (world-to-camera rotation, centre), placed where another camera sees it
// exactly alike: the two fits of one view whose worlds differ in the
// camera's pitch, roll and path (fit.cc, stage 5).
struct RootPlacement {
  Eigen::Vector3d position_m;
  Eigen::Quaterniond orientation;
};
inline RootPlacement CarryBetweenCameras(const Eigen::Matrix3d& from_rotation,
                                         const Eigen::Vector3d& from_centre_m,
                                         const Eigen::Matrix3d& to_rotation,
                                         const Eigen::Vector3d& to_centre_m,
                                         const RootPlacement& body) {
  const Eigen::Matrix3d to_from_from = to_rotation.transpose() * from_rotation;
  return {to_centre_m + to_from_from * (body.position_m - from_centre_m),
          (Eigen::Quaterniond(to_from_from) * body.orientation).normalized()};
}

// The estimated camera as a PinholeCamera for an image of the given size.
PinholeCamera ToPinholeCamera(double focal_px, const double* pitch_roll_rad,
                              const double* centre_m, int width_px,
                              int height_px, double yaw_rad = 0.0);

// Pitch (positive looks down) and roll of any camera, in radians, by the
// convention above: for measuring a fit against a true camera.
Eigen::Vector2d CameraPitchRollRad(const PinholeCamera& camera);

// The heading (rad, from +x toward +y) the camera looks along.
double CameraYawRad(const PinholeCamera& camera);

}  // namespace m2d

#endif  // MIMIC2D_FIT_CAMERA_MODEL_H_
