// camera: rigs of K views placed around a subject.
#ifndef MIMIC2D_CAMERA_RIG_H_
#define MIMIC2D_CAMERA_RIG_H_

#include <string>
#include <vector>

#include "camera/pinhole.h"

namespace m2d {

struct NamedCamera {
  std::string name;
  PinholeCamera camera;
};

// K cameras on a circle around `target_m`, all looking at it.
struct RigOptions {
  int num_views = 4;
  double first_azimuth_deg = 30.0;  // azimuth of view 0, about +z from +x
  double azimuth_span_deg = 360.0;  // views are spread evenly over the span
  double elevation_deg = 10.0;      // above the horizontal through target
  double distance_m = 4.5;          // camera centre to target
  // View k of K sits at elevation_deg + k/(K-1) * elevation_span_deg and
  // distance_m + k/(K-1) * distance_span_m: a rig whose views differ in
  // height and range as well as azimuth (AIST++-like). 0: all alike.
  double elevation_span_deg = 0.0;
  double distance_span_m = 0.0;
  double focal_px = 1000.0;  // fx = fy
  int width_px = 1920;
  int height_px = 1080;
  Eigen::Vector3d target_m = {0.0, 0.0, 0.9};  // the subject's centre

  // Throws ConfigError naming the first bad setting.
  void Validate() const;
};

std::vector<NamedCamera> MakeRig(const RigOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_CAMERA_RIG_H_
