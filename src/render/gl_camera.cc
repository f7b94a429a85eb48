#include "render/gl_camera.h"

#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

int EvenCeil(double size_px) {
  int size = static_cast<int>(std::ceil(size_px - 1e-9));
  return size + (size % 2);
}

}  // namespace

mjvGLCamera GlCameraFromPinhole(const PinholeCamera& camera, double near_m,
                                double far_m) {
  const Intrinsics& k = camera.intrinsics();
  if (!(k.fx_px > 0 && k.fy_px > 0)) {
    throw ConfigError("camera focal lengths must be positive");
  }
  if (std::abs(k.fx_px - k.fy_px) > kMaxPixelAspectError * k.fy_px) {
    throw ConfigError("camera has non-square pixels (fx " +
                      std::to_string(k.fx_px) + " px, fy " +
                      std::to_string(k.fy_px) +
                      " px): MuJoCo 2.2.2's renderer cannot draw them");
  }
  if (!(near_m > 0 && far_m > near_m)) {
    throw ConfigError("render clip range must satisfy 0 < near < far");
  }
  mjvGLCamera gl = {};
  const Eigen::Matrix3d& r = camera.rotation_world_to_camera();
  const Eigen::Vector3d center = camera.CenterWorld();
  const Eigen::Vector3d forward = r.row(2).transpose();
  const Eigen::Vector3d up = -r.row(1).transpose();
  for (int i = 0; i < 3; ++i) {
    gl.pos[i] = static_cast<float>(center[i]);
    gl.forward[i] = static_cast<float>(forward[i]);
    gl.up[i] = static_cast<float>(up[i]);
  }
  // Image edges on the near plane: u = 0 and u = W at x = near (u - cx)/fx,
  // v = 0 (top, GL y up) and v = H at y = near (cy - v)/fy.
  const double left = -near_m * k.cx_px / k.fx_px;
  const double right = near_m * (k.width_px - k.cx_px) / k.fx_px;
  gl.frustum_center = static_cast<float>(0.5 * (left + right));
  gl.frustum_top = static_cast<float>(near_m * k.cy_px / k.fy_px);
  gl.frustum_bottom =
      static_cast<float>(-near_m * (k.height_px - k.cy_px) / k.fy_px);
  gl.frustum_near = static_cast<float>(near_m);
  gl.frustum_far = static_cast<float>(far_m);
  return gl;
}

PinholeCamera ScaleCamera(const PinholeCamera& camera, double scale) {
  if (!(std::isfinite(scale) && scale > 0)) {
    throw ConfigError("render scale must be a positive number");
  }
  Intrinsics k = camera.intrinsics();
  k.fx_px *= scale;
  k.fy_px *= scale;
  k.cx_px *= scale;
  k.cy_px *= scale;
  k.width_px = EvenCeil(k.width_px * scale);
  k.height_px = EvenCeil(k.height_px * scale);
  return PinholeCamera(k, camera.rotation_world_to_camera(),
                       camera.translation_m());
}

PinholeCamera CropCamera(const PinholeCamera& camera, double x0_px,
                         double y0_px, double zoom) {
  if (!(std::isfinite(zoom) && zoom > 0 && std::isfinite(x0_px) &&
        std::isfinite(y0_px))) {
    throw ConfigError("crop: zoom must be positive and the corner finite");
  }
  Intrinsics k = camera.intrinsics();
  k.fx_px *= zoom;
  k.fy_px *= zoom;
  k.cx_px = (k.cx_px - x0_px) * zoom;
  k.cy_px = (k.cy_px - y0_px) * zoom;
  return PinholeCamera(k, camera.rotation_world_to_camera(),
                       camera.translation_m());
}

void OrbitCameraOptions::Validate() const {
  if (!(std::isfinite(azimuth_deg) && std::isfinite(elevation_deg))) {
    throw ConfigError("orbit camera: azimuth and elevation must be finite");
  }
  if (!(std::abs(elevation_deg) < 89.0)) {
    throw ConfigError("orbit camera: elevation must be within (-89, 89) deg");
  }
  if (!(std::isfinite(distance_m) && distance_m > 0)) {
    throw ConfigError("orbit camera: distance must be positive");
  }
  if (!(fovy_deg > 1.0 && fovy_deg < 170.0)) {
    throw ConfigError("orbit camera: field of view must be in (1, 170) deg");
  }
}

PinholeCamera OrbitCamera(const OrbitCameraOptions& options,
                          const Eigen::Vector3d& target_m, int width_px,
                          int height_px) {
  options.Validate();
  const double azimuth = options.azimuth_deg * M_PI / 180.0;
  const double elevation = options.elevation_deg * M_PI / 180.0;
  const Eigen::Vector3d forward(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth),
                                std::sin(elevation));
  Intrinsics k;
  k.width_px = width_px;
  k.height_px = height_px;
  k.fy_px = 0.5 * height_px / std::tan(0.5 * options.fovy_deg * M_PI / 180.0);
  k.fx_px = k.fy_px;
  k.cx_px = 0.5 * width_px;
  k.cy_px = 0.5 * height_px;
  return PinholeCamera::LookAt(k, target_m - options.distance_m * forward,
                               target_m);
}

}  // namespace m2d
