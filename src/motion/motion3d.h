// motion: 3D motions (root trajectory + local joint rotations over time) and
// their forward kinematics to joint and keypoint positions.
#ifndef MIMIC2D_MOTION_MOTION3D_H_
#define MIMIC2D_MOTION_MOTION3D_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "motion/skeleton.h"

namespace m2d {

// One frame of a skeleton's pose. local_rotations[0] is the root's world
// orientation; local_rotations[j] rotates joint j's frame relative to its
// parent (identity for fixed joints; about `axis` for revolute ones).
struct Pose3D {
  Eigen::Vector3d root_position_m = Eigen::Vector3d::Zero();
  std::vector<Eigen::Quaterniond> local_rotations;
};

// A motion sampled at a uniform rate.
struct Motion3D {
  std::shared_ptr<const Skeleton> skeleton;
  double fps = 30.0;
  bool loops = false;  // the last frame closes a cycle (DeepMimic "wrap")
  std::vector<Pose3D> frames;

  int num_frames() const { return static_cast<int>(frames.size()); }
  double duration_s() const {
    return frames.empty() ? 0.0 : (num_frames() - 1) / fps;
  }
};

// World positions (and orientations, when requested) of every joint.
void ForwardKinematics(
    const Skeleton& skeleton, const Pose3D& pose,
    std::vector<Eigen::Vector3d>* joint_positions_m,
    std::vector<Eigen::Quaterniond>* joint_orientations = nullptr);

// World positions of a keypoint map's keypoints, in layout order.
std::vector<Eigen::Vector3d> KeypointPositions(const Skeleton& skeleton,
                                               const KeypointMap& map,
                                               const Pose3D& pose);

// Interpolates poses (lerp for position, slerp for rotations).
Pose3D InterpolatePose(const Pose3D& a, const Pose3D& b, double alpha);

// The pose at time `time_s` (clamped to the motion's span).
Pose3D SamplePose(const Motion3D& motion, double time_s);

// The motion resampled at `fps`, covering the same span.
Motion3D ResampleMotion(const Motion3D& motion, double fps);

// What a looped cycle's net heading turn does across cycles.
enum class LoopHeading {
  kAccumulate,  // each cycle turns by it once more (DeepMimic "wrap"): the
                // DeepMimic walk turns about 6 deg per cycle, 100 deg in 20 s
  kStraight,    // it is spread back over the cycle: the cycles chain into a
                // straight path, the heading the first frame's
};
const char* SettingName(LoopHeading heading);  // "accumulate", "straight"
bool ParseSetting(const std::string& text, LoopHeading* heading);
inline std::string SettingChoices(LoopHeading) {
  return "accumulate, straight";
}

// A looping motion repeated until it lasts at least `duration_s`: each new
// cycle continues from where the previous one ended, with the root's
// horizontal translation and (per `heading`) heading accumulated. A
// non-looping motion is returned unchanged.
Motion3D ExtendLoop(const Motion3D& motion, double duration_s,
                    LoopHeading heading = LoopHeading::kAccumulate);

// Heading (yaw about +z, radians) of an orientation whose local +x is the
// character's forward direction.
double HeadingAngle(const Eigen::Quaterniond& rotation);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_MOTION3D_H_
