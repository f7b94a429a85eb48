#include "motion/object_track.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace m2d {

std::optional<Eigen::Vector3d> PointOnHorizontalPlane(
    const PinholeCamera& camera, const Eigen::Vector2d& pixel_px,
    double height_m) {
  const Eigen::Vector3d direction = camera.RayDirectionWorld(pixel_px);
  const Eigen::Vector3d centre = camera.CenterWorld();
  if (!direction.allFinite() || std::abs(direction.z()) < 1e-9) return {};
  const double along = (height_m - centre.z()) / direction.z();
  if (!(along > 0)) return {};
  return centre + along * direction;
}

ObjectTrack3D RollingObjectFromPixels(const ObjectTrack2D& track,
                                      const std::vector<PinholeCamera>& cameras,
                                      double fps, const RollingBall& ball,
                                      const std::string& source) {
  // Outline: place every frame that can be placed; fill the others from
  // the placed frames around them (linear between two, rolling on after
  // the last, resting before the first).
  const double radius_m = ball.radius_m;
  const int num_frames = static_cast<int>(track.points.size());
  if (cameras.empty() ||
      (cameras.size() != 1 && static_cast<int>(cameras.size()) != num_frames)) {
    throw InputError(source, "object '" + track.name +
                                 "': " + std::to_string(cameras.size()) +
                                 " cameras for " + std::to_string(num_frames) +
                                 " frames");
  }
  std::vector<std::optional<Eigen::Vector3d>> placed(num_frames);
  for (int t = 0; t < num_frames; ++t) {
    const Keypoint2D& point = track.points[t];
    if (!point.IsPresent()) continue;
    placed[t] = PointOnHorizontalPlane(
        cameras.size() == 1 ? cameras[0] : cameras[t], point.Pixel(), radius_m);
  }
  ObjectTrack3D out;
  out.name = track.name;
  out.positions_m.resize(num_frames);
  // After the last placed frame: rolling on from there.
  int last = num_frames - 1;
  while (last >= 0 && !placed[last]) --last;
  Eigen::Vector3d roll_velocity_m_s = Eigen::Vector3d::Zero();
  for (int before = last - 1; before >= 0 && last >= 0; --before) {
    if (!placed[before]) continue;
    roll_velocity_m_s =
        (*placed[last] - *placed[before]) * fps / (last - before);
    roll_velocity_m_s.z() = 0.0;
    break;
  }
  int previous = -1;
  for (int t = 0; t < num_frames; ++t) {
    if (placed[t]) {
      out.positions_m[t] = *placed[t];
      previous = t;
      continue;
    }
    int next = t + 1;
    while (next < num_frames && !placed[next]) ++next;
    if (previous < 0 && next >= num_frames) {
      throw InputError(source, "object '" + track.name +
                                   "' is not seen on the floor in any frame "
                                   "(missing, or above the horizon)");
    }
    if (previous < 0) {
      out.positions_m[t] = *placed[next];
    } else if (next >= num_frames) {
      // Distance rolled in (t - last) frames under constant deceleration,
      // capped where the ball stops.
      const double speed = roll_velocity_m_s.norm();
      const double elapsed_s = (t - last) / fps;
      const double stop_s = speed / ball.deceleration_m_s2;
      const double moving_s = std::min(elapsed_s, stop_s);
      const double distance_m =
          speed * moving_s - 0.5 * ball.deceleration_m_s2 * moving_s * moving_s;
      out.positions_m[t] = *placed[last];
      if (speed > 0)
        out.positions_m[t] += roll_velocity_m_s / speed * distance_m;
    } else {
      const double alpha =
          static_cast<double>(t - previous) / (next - previous);
      out.positions_m[t] =
          (1 - alpha) * *placed[previous] + alpha * *placed[next];
    }
  }
  return out;
}

}  // namespace m2d
