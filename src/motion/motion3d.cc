#include "motion/motion3d.h"

#include <algorithm>
#include <cmath>

#include "common/settings.h"

namespace m2d {

void ForwardKinematics(const Skeleton& skeleton, const Pose3D& pose,
                       std::vector<Eigen::Vector3d>* joint_positions_m,
                       std::vector<Eigen::Quaterniond>* joint_orientations) {
  // Parents precede children, so one pass in order composes every chain.
  const int num_joints = skeleton.num_joints();
  std::vector<Eigen::Quaterniond> orientations(num_joints);
  joint_positions_m->resize(num_joints);
  for (int j = 0; j < num_joints; ++j) {
    const SkeletonJoint& joint = skeleton.joints[j];
    if (joint.parent < 0) {
      (*joint_positions_m)[j] = pose.root_position_m + joint.offset_m;
      orientations[j] = pose.local_rotations[j];
    } else {
      const Eigen::Quaterniond& parent = orientations[joint.parent];
      (*joint_positions_m)[j] =
          (*joint_positions_m)[joint.parent] + parent * joint.offset_m;
      orientations[j] = parent * pose.local_rotations[j];
    }
  }
  if (joint_orientations != nullptr) *joint_orientations = orientations;
}

std::vector<Eigen::Vector3d> KeypointPositions(const Skeleton& skeleton,
                                               const KeypointMap& map,
                                               const Pose3D& pose) {
  std::vector<Eigen::Vector3d> joints;
  std::vector<Eigen::Quaterniond> orientations;
  ForwardKinematics(skeleton, pose, &joints, &orientations);
  std::vector<Eigen::Vector3d> keypoints;
  keypoints.reserve(map.anchors.size());
  for (const KeypointAnchor& anchor : map.anchors) {
    keypoints.push_back(joints[anchor.joint] +
                        orientations[anchor.joint] * anchor.offset_m);
  }
  return keypoints;
}

Pose3D InterpolatePose(const Pose3D& a, const Pose3D& b, double alpha) {
  Pose3D out;
  out.root_position_m =
      (1.0 - alpha) * a.root_position_m + alpha * b.root_position_m;
  out.local_rotations.resize(a.local_rotations.size());
  for (size_t j = 0; j < a.local_rotations.size(); ++j) {
    out.local_rotations[j] =
        a.local_rotations[j].slerp(alpha, b.local_rotations[j]);
  }
  return out;
}

Pose3D SamplePose(const Motion3D& motion, double time_s) {
  double position = std::clamp(time_s * motion.fps, 0.0,
                               static_cast<double>(motion.num_frames() - 1));
  int index = std::min(static_cast<int>(position), motion.num_frames() - 2);
  if (index < 0) return motion.frames.front();
  return InterpolatePose(motion.frames[index], motion.frames[index + 1],
                         position - index);
}

Motion3D ResampleMotion(const Motion3D& motion, double fps) {
  Motion3D out = motion;
  out.fps = fps;
  out.frames.clear();
  int count =
      static_cast<int>(std::floor(motion.duration_s() * fps + 1e-9)) + 1;
  for (int i = 0; i < count; ++i)
    out.frames.push_back(SamplePose(motion, i / fps));
  return out;
}

double HeadingAngle(const Eigen::Quaterniond& rotation) {
  Eigen::Vector3d forward = rotation * Eigen::Vector3d::UnitX();
  return std::atan2(forward.y(), forward.x());
}

namespace {

// Recorded cycles rarely close exactly: the DeepMimic walk's last frame
// misses its first by 0.50 rad at the right shoulder, a one-frame jump at
// every seam (and a wild velocity for a state initialized there). Spreads
// each rotation's mismatch, and the root height's, linearly over the cycle
// so that the last frame repeats the first up to the heading `cycle_turn`
// that ExtendLoop accumulates.
Motion3D CloseLoopSeam(const Motion3D& motion,
                       const Eigen::Quaterniond& cycle_turn) {
  Motion3D closed = motion;
  const Pose3D& first = motion.frames.front();
  const Pose3D& last = motion.frames.back();
  const int num_rotations = static_cast<int>(first.local_rotations.size());
  std::vector<Eigen::Quaterniond> mismatch(num_rotations);
  for (int j = 0; j < num_rotations; ++j) {
    Eigen::Quaterniond target = first.local_rotations[j];
    if (j == 0) target = cycle_turn * target;  // the root turns every cycle
    mismatch[j] = (target * last.local_rotations[j].inverse()).normalized();
  }
  const double height_mismatch_m =
      first.root_position_m.z() - last.root_position_m.z();
  const int n = motion.num_frames();
  for (int i = 1; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    Pose3D& pose = closed.frames[i];
    for (int j = 0; j < num_rotations; ++j) {
      pose.local_rotations[j] =
          (Eigen::Quaterniond::Identity().slerp(t, mismatch[j]) *
           pose.local_rotations[j])
              .normalized();
    }
    pose.root_position_m.z() += t * height_mismatch_m;
  }
  return closed;
}

}  // namespace

const char* SettingName(LoopHeading heading) {
  return heading == LoopHeading::kStraight ? "straight" : "accumulate";
}

bool ParseSetting(const std::string& text, LoopHeading* heading) {
  return ParseSettingByName(
      text, {LoopHeading::kAccumulate, LoopHeading::kStraight}, heading);
}

Motion3D ExtendLoop(const Motion3D& looping_motion, double duration_s,
                    LoopHeading heading) {
  if (!looping_motion.loops || looping_motion.num_frames() < 2 ||
      looping_motion.duration_s() >= duration_s)
    return looping_motion;
  // One cycle spans frames [0, n-1]; frame n-1 is frame 0 of the next cycle.
  // The cycle's net motion is the heading turn and horizontal shift from
  // frame 0 to frame n-1; each repetition applies it once more.
  double turn = HeadingAngle(looping_motion.frames.back().local_rotations[0]) -
                HeadingAngle(looping_motion.frames.front().local_rotations[0]);
  turn = std::remainder(turn, 2.0 * M_PI);
  Motion3D cycle = looping_motion;
  if (heading == LoopHeading::kStraight) {
    // Frame i turns back by the share i / (n-1) of the turn, about the first
    // frame's root: the root's orientation and its horizontal path alike.
    const Eigen::Vector3d anchor = cycle.frames.front().root_position_m;
    const int n = cycle.num_frames();
    for (int i = 1; i < n; ++i) {
      const Eigen::Quaterniond back(
          Eigen::AngleAxisd(-turn * i / (n - 1.0), Eigen::Vector3d::UnitZ()));
      Pose3D& pose = cycle.frames[i];
      Eigen::Vector3d relative = pose.root_position_m - anchor;
      const double height_m = pose.root_position_m.z();
      relative.z() = 0.0;
      pose.root_position_m = anchor + back * relative;
      pose.root_position_m.z() = height_m;
      pose.local_rotations[0] = (back * pose.local_rotations[0]).normalized();
    }
    turn = 0.0;
  }
  Eigen::Quaterniond cycle_turn(
      Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()));
  const Motion3D motion = CloseLoopSeam(cycle, cycle_turn);
  const Pose3D& first = motion.frames.front();
  const Pose3D& last = motion.frames.back();

  Motion3D out = motion;
  Eigen::Quaterniond turn_so_far = Eigen::Quaterniond::Identity();
  Eigen::Vector3d end_position = last.root_position_m;
  while (out.duration_s() < duration_s) {
    turn_so_far = cycle_turn * turn_so_far;
    // Place the new cycle so that its frame 0 coincides with the previous
    // cycle's last frame (horizontally), turned by the accumulated heading.
    Eigen::Vector3d anchor = first.root_position_m;
    for (int i = 1; i < motion.num_frames(); ++i) {
      Pose3D pose = motion.frames[i];
      Eigen::Vector3d relative = pose.root_position_m - anchor;
      relative.z() = 0.0;
      pose.root_position_m = end_position + turn_so_far * relative;
      pose.root_position_m.z() = motion.frames[i].root_position_m.z();
      pose.local_rotations[0] = turn_so_far * pose.local_rotations[0];
      out.frames.push_back(pose);
    }
    end_position = out.frames.back().root_position_m;
  }
  return out;
}

}  // namespace m2d
