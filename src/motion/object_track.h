// motion: an object's 3D track from one view's 2D — a ball rolling on the
// floor, its centre where its pixel's ray meets the plane one radius up.
#ifndef MIMIC2D_MOTION_OBJECT_TRACK_H_
#define MIMIC2D_MOTION_OBJECT_TRACK_H_

#include <optional>
#include <vector>

#include "camera/pinhole.h"
#include "motion/bundle.h"
#include "motion/clip2d.h"

namespace m2d {

// Where the ray from `camera` through `pixel_px` meets the horizontal plane
// at `height_m`; none when it meets it behind the camera or runs parallel.
std::optional<Eigen::Vector3d> PointOnHorizontalPlane(
    const PinholeCamera& camera, const Eigen::Vector2d& pixel_px,
    double height_m);

// How a ball rolls where no frame shows it.
struct RollingBall {
  double radius_m = 0.11;  // a size-5 soccer ball
  // Rolling resistance: assets/characters/soccer_ball.xml's ball slows by
  // 0.45-0.5 m/s^2 on our floor (docs/simulation.md).
  double deceleration_m_s2 = 0.45;
};

// `track` (one view's 2D of an object, `fps` frames a second) as 3D, seen
// by `cameras` (1, or one per frame): each frame's centre on the plane one
// radius above the floor (z = 0), where a rolling ball is. Frames where the
// object is not seen, or whose ray does not meet that plane in front of the
// camera (above the horizon), are filled: between two placed frames,
// linearly; after the last, the ball rolls on at its last velocity (the last
// two placed frames') slowing by `ball.deceleration_m_s2` until it stops
// (it left the image); before the first, it rests where first placed. Exact
// for a ball on the floor; a ball in the air comes out farther along its
// ray, on the plane. InputError naming `source` when no frame can be placed.
ObjectTrack3D RollingObjectFromPixels(const ObjectTrack2D& track,
                                      const std::vector<PinholeCamera>& cameras,
                                      double fps, const RollingBall& ball,
                                      const std::string& source);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_OBJECT_TRACK_H_
