#include "camera/rig.h"

#include <cmath>

#include "common/error.h"

namespace m2d {

void RigOptions::Validate() const {
  // More views than this is a typo (100000 views ran out of memory).
  constexpr int kMaxViews = 256;
  constexpr int kMaxImageSidePx = 65536;
  if (num_views < 1 || num_views > kMaxViews) {
    throw ConfigError("rig: num_views must be in [1, " +
                      std::to_string(kMaxViews) + "], not " +
                      std::to_string(num_views));
  }
  if (!std::isfinite(first_azimuth_deg) || !std::isfinite(azimuth_span_deg)) {
    throw ConfigError("rig: azimuths must be finite");
  }
  if (!(distance_m > 0.1) || !std::isfinite(distance_m))
    throw ConfigError("rig: distance_m must be finite and > 0.1");
  if (!std::isfinite(distance_span_m) || !(distance_m + distance_span_m > 0.1))
    throw ConfigError(
        "rig: distance_m + distance_span_m (the last view's distance) must be "
        "finite and > 0.1");
  if (!std::isfinite(elevation_span_deg) ||
      !(std::abs(elevation_deg + elevation_span_deg) < 89.0)) {
    throw ConfigError(
        "rig: |elevation_deg + elevation_span_deg| (the last view's "
        "elevation) must be < 89");
  }
  if (!(focal_px > 0) || !std::isfinite(focal_px))
    throw ConfigError("rig: focal_px must be finite and > 0");
  if (width_px < 1 || height_px < 1 || width_px > kMaxImageSidePx ||
      height_px > kMaxImageSidePx) {
    throw ConfigError("rig: image sides must be in [1, " +
                      std::to_string(kMaxImageSidePx) + "] px");
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

  std::vector<NamedCamera> rig;
  for (int k = 0; k < options.num_views; ++k) {
    double share = options.num_views > 1 ? k / (options.num_views - 1.0) : 0.0;
    double azimuth = (options.first_azimuth_deg + k * step_deg) * M_PI / 180.0;
    double elevation =
        (options.elevation_deg + share * options.elevation_span_deg) * M_PI /
        180.0;
    double distance = options.distance_m + share * options.distance_span_m;
    Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth),
                              std::sin(elevation));
    Eigen::Vector3d eye = options.target_m + distance * direction;
    rig.push_back({"view" + std::to_string(k),
                   PinholeCamera::LookAt(intrinsics, eye, options.target_m)});
  }
  return rig;
}

}  // namespace m2d
