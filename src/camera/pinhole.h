// camera: pinhole cameras, their projection and its Jacobian, camera rigs
// around a subject, and camera sets as JSON.
//
// Conventions: world is Z-up, metres. Camera frame follows OpenCV: x right,
// y down, z forward (optical axis). Pixels are (u right, v down) with the
// origin at the image's top-left corner.
#ifndef MIMIC2D_CAMERA_PINHOLE_H_
#define MIMIC2D_CAMERA_PINHOLE_H_

#include <Eigen/Core>
#include <string>

namespace m2d {

// Points closer to the image plane than this are "behind" the camera.
inline constexpr double kMinProjectDepth_m = 1e-3;

struct Intrinsics {
  double fx_px = 1000.0;  // focal length in pixels, horizontal
  double fy_px = 1000.0;  // focal length in pixels, vertical
  double cx_px = 960.0;   // principal point
  double cy_px = 540.0;
  int width_px = 1920;  // image size
  int height_px = 1080;
};

// The result of projecting one point. Points behind the camera (depth below
// kMinProjectDepth_m) have in_front == false and NaN pixels: callers must
// treat them as unobserved (the environment ends the episode on them).
struct Projection {
  Eigen::Vector2d pixel_px;
  double depth_m = 0.0;
  bool in_front = false;
};

class PinholeCamera {
 public:
  PinholeCamera() = default;
  PinholeCamera(const Intrinsics& intrinsics,
                const Eigen::Matrix3d& rotation_world_to_camera,
                const Eigen::Vector3d& translation_m);

  // A camera at `eye_m` looking at `target_m`, with `up` (world) pointing up
  // in the image. Throws ConfigError when eye == target or the view is
  // parallel to `up`.
  static PinholeCamera LookAt(const Intrinsics& intrinsics,
                              const Eigen::Vector3d& eye_m,
                              const Eigen::Vector3d& target_m,
                              const Eigen::Vector3d& up = {0, 0, 1});

  Projection Project(const Eigen::Vector3d& point_world_m) const;

  // d(pixel)/d(point_world) at `point_world_m` (2x3). Zero for points behind
  // the camera, where the projection is undefined.
  Eigen::Matrix<double, 2, 3> ProjectJacobian(
      const Eigen::Vector3d& point_world_m) const;

  Eigen::Vector3d ToCamera(const Eigen::Vector3d& point_world_m) const {
    return rotation_ * point_world_m + translation_m_;
  }
  // The camera centre in world coordinates.
  Eigen::Vector3d CenterWorld() const {
    return -rotation_.transpose() * translation_m_;
  }
  // The world direction (not normalized; unit depth along the optical axis)
  // of the ray from the camera centre through `pixel_px`.
  Eigen::Vector3d RayDirectionWorld(const Eigen::Vector2d& pixel_px) const;
  // The same camera moved by `offset_m` in the world (orientation kept).
  PinholeCamera Translated(const Eigen::Vector3d& offset_m) const;

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Eigen::Matrix3d& rotation_world_to_camera() const { return rotation_; }
  const Eigen::Vector3d& translation_m() const { return translation_m_; }

 private:
  Intrinsics intrinsics_;
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation_m_ = Eigen::Vector3d::Zero();
};

}  // namespace m2d

#endif  // MIMIC2D_CAMERA_PINHOLE_H_
