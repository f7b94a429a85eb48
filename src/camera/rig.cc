#include "camera/rig.h"

#include <cmath>

#include "common/error.h"

namespace m2d {

void RigOptions::Validate() const {
  if (num_views < 1) throw ConfigError("rig: num_views must be >= 1");
  if (!(distance_m > 0.1)) throw ConfigError("rig: distance_m must be > 0.1");
  if (!(focal_px > 0)) throw ConfigError("rig: focal_px must be > 0");
  if (width_px < 1 || height_px < 1) {
    throw ConfigError("rig: image size must be positive");
  }
  if (!(std::abs(elevation_deg) < 89.0)) {
    throw ConfigError("rig: |elevation_deg| must be < 89");
  }
  if (!target_m.allFinite()) throw ConfigError("rig: target_m must be finite");
}

std::vector<NamedCamera> MakeRig(const RigOptions& options) {
  options.Validate();
  Intrinsics intrinsics;
  intrinsics.fx_px = intrinsics.fy_px = options.focal_px;
  intrinsics.width_px = options.width_px;
  intrinsics.height_px = options.height_px;
  intrinsics.cx_px = 0.5 * options.width_px;
  intrinsics.cy_px = 0.5 * options.height_px;

  // A full circle spreads K views over 360/K steps; a partial arc includes
  // both of its ends.
  bool full_circle = std::abs(options.azimuth_span_deg - 360.0) < 1e-9;
  int intervals =
      full_circle ? options.num_views : std::max(1, options.num_views - 1);
  double step_deg = options.azimuth_span_deg / intervals;
  double elevation = options.elevation_deg * M_PI / 180.0;

  std::vector<NamedCamera> rig;
  for (int k = 0; k < options.num_views; ++k) {
    double azimuth = (options.first_azimuth_deg + k * step_deg) * M_PI / 180.0;
    Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth),
                              std::sin(elevation));
    Eigen::Vector3d eye = options.target_m + options.distance_m * direction;
    rig.push_back({"view" + std::to_string(k),
                   PinholeCamera::LookAt(intrinsics, eye, options.target_m)});
  }
  return rig;
}

}  // namespace m2d
