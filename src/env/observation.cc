#include "env/observation.h"

#include <algorithm>
#include <cmath>

namespace m2d {
namespace {

void WriteVector(const Eigen::Vector3d& v, float* out) {
  out[0] = static_cast<float>(v.x());
  out[1] = static_cast<float>(v.y());
  out[2] = static_cast<float>(v.z());
}

}  // namespace

Eigen::Quaterniond InverseHeadingRotation(const Eigen::Quaterniond& root) {
  Eigen::Vector3d forward = root * Eigen::Vector3d::UnitX();
  double heading = std::atan2(forward.y(), forward.x());
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(-heading, Eigen::Vector3d::UnitZ()));
}

void WriteProprioception(const BodyKinematics& bodies, float* out) {
  const Eigen::Vector3d& root = bodies.positions_m[0];
  Eigen::Quaterniond to_heading =
      InverseHeadingRotation(bodies.orientations[0]);
  *out++ = static_cast<float>(root.z());
  for (size_t b = 0; b < bodies.positions_m.size(); ++b) {
    WriteVector(to_heading * (bodies.positions_m[b] - root), out);
    Eigen::Matrix3d rotation =
        (to_heading * bodies.orientations[b]).toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
      out[3 + i] = static_cast<float>(rotation(i, 0));
      out[6 + i] = static_cast<float>(rotation(i, 1));
    }
    WriteVector(to_heading * bodies.linear_velocities_m_s[b], out + 9);
    WriteVector(to_heading * bodies.angular_velocities_rad_s[b], out + 12);
    out += ObservationLayout::kBodyFeatures;
  }
}

void WriteObjectState(const BodyKinematics& bodies,
                      const std::vector<Eigen::Vector3d>& object_positions_m,
                      const std::vector<Eigen::Vector3d>& object_velocities_m_s,
                      float* out) {
  Eigen::Quaterniond to_heading =
      InverseHeadingRotation(bodies.orientations[0]);
  for (size_t i = 0; i < object_positions_m.size(); ++i) {
    WriteVector(to_heading * (object_positions_m[i] - bodies.positions_m[0]),
                out);
    WriteVector(to_heading * (object_velocities_m_s[i] -
                              bodies.linear_velocities_m_s[0]),
                out + 3);
    out += ObservationLayout::kObjectFeatures;
  }
}

void WriteNormalizedPoints(const Keypoint2D* points, int num_points,
                           const ImageNormalization& normalization,
                           float* out) {
  const double inverse_scale = 1.0 / normalization.scale_px;
  for (int j = 0; j < num_points;
       ++j, out += ObservationLayout::kPointFeatures) {
    const Keypoint2D& point = points[j];
    if (!point.IsPresent()) {
      out[0] = out[1] = out[2] = 0.0f;
      continue;
    }
    double x = (point.x_px - normalization.root_px.x()) * inverse_scale;
    double y = (point.y_px - normalization.root_px.y()) * inverse_scale;
    out[0] = std::clamp(static_cast<float>(x), -kMaxNormalizedCoordinate,
                        kMaxNormalizedCoordinate);
    out[1] = std::clamp(static_cast<float>(y), -kMaxNormalizedCoordinate,
                        kMaxNormalizedCoordinate);
    out[2] = 1.0f;
  }
}

void WriteRootRelativePoints(const Eigen::Vector3d* points_m, int num_points,
                             const Eigen::Vector3d& root_m,
                             const Eigen::Quaterniond& to_heading, float* out) {
  for (int j = 0; j < num_points; ++j, out += 3) {
    const Eigen::Vector3d local = to_heading * (points_m[j] - root_m);
    for (int i = 0; i < 3; ++i) {
      out[i] = static_cast<float>(
          std::clamp(local[i], -static_cast<double>(kMaxNormalizedCoordinate),
                     static_cast<double>(kMaxNormalizedCoordinate)));
    }
  }
}

void WriteCriticOnlyInputs(const BodyKinematics& bodies,
                           const Eigen::Vector3d* reference_now_m,
                           const Eigen::Vector3d* reference_next_m,
                           int num_keypoints,
                           const Eigen::Vector3d& camera_center_m,
                           const Eigen::Matrix3d& camera_to_world, float* out) {
  const Eigen::Vector3d& root = bodies.positions_m[0];
  const Eigen::Quaterniond to_heading =
      InverseHeadingRotation(bodies.orientations[0]);
  WriteRootRelativePoints(reference_now_m, num_keypoints, root, to_heading,
                          out);
  out += 3 * num_keypoints;
  WriteRootRelativePoints(reference_next_m, num_keypoints, root, to_heading,
                          out);
  out += 3 * num_keypoints;
  WriteRootRelativePoints(&camera_center_m, 1, root, to_heading, out);
  const Eigen::Matrix3d axes = to_heading.toRotationMatrix() * camera_to_world;
  for (int i = 0; i < 3; ++i) {
    out[3 + i] = static_cast<float>(axes(i, 0));
    out[6 + i] = static_cast<float>(axes(i, 1));
  }
}

}  // namespace m2d
