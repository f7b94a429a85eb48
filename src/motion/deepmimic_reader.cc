// motion: the DeepMimic motion-file reader.
#include <algorithm>
#include <cctype>
#include <cmath>

#include "common/error.h"
#include "common/file_io.h"
#include "common/json_fields.h"
#include "motion/motion_io.h"

namespace m2d {

Eigen::Quaterniond YUpToZUp() {
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
}

namespace {

// Number of values a joint takes in a DeepMimic frame.
int ChannelCount(JointType type) {
  switch (type) {
    case JointType::kSpherical:
      return 4;
    case JointType::kRevolute:
      return 1;
    default:
      return 0;
  }
}

Eigen::Quaterniond ReadQuaternion(const JsonCursor& frame, size_t offset) {
  Eigen::Quaterniond q(frame.At(offset).Number(), frame.At(offset + 1).Number(),
                       frame.At(offset + 2).Number(),
                       frame.At(offset + 3).Number());
  double norm = q.norm();
  if (norm < 1e-6) frame.At(offset).Fail("zero-length quaternion");
  return Eigen::Quaterniond(q.coeffs() / norm);
}

}  // namespace

Motion3D ReadDeepMimicMotion(const std::string& path,
                             std::shared_ptr<const Skeleton> skeleton,
                             double fps) {
  // Outline: parse JSON, check each frame's length against the skeleton's
  // channels, convert Y-up to Z-up, resample to a uniform rate.
  nlohmann::json json = ReadJsonFile(path);
  JsonCursor root(json, path);
  Motion3D raw;
  raw.skeleton = skeleton;
  // DeepMimic writes "wrap" or "none"; compare without case ("Wrap").
  if (root.Has("Loop")) {
    std::string loop = root.Field("Loop").String();
    for (char& c : loop) c = static_cast<char>(std::tolower(c));
    raw.loops = loop == "wrap";
  }

  size_t frame_length = 1 + 3 + 4;
  for (int j = 1; j < skeleton->num_joints(); ++j) {
    frame_length += ChannelCount(skeleton->joints[j].type);
  }
  JsonCursor frames = root.Field("Frames");
  size_t num_frames = frames.ArraySize();
  if (num_frames == 0) frames.Fail("no frames");

  const Eigen::Quaterniond to_world = YUpToZUp();
  const Eigen::Quaterniond from_world = to_world.conjugate();
  std::vector<double> durations_s;
  for (size_t i = 0; i < num_frames; ++i) {
    JsonCursor frame = frames.At(i);
    size_t length = frame.ArraySize();
    if (length != frame_length) {
      frame.Fail("has " + std::to_string(length) + " values, skeleton '" +
                 skeleton->name + "' needs " + std::to_string(frame_length));
    }
    durations_s.push_back(frame.At(0).Number());
    Pose3D pose;
    Eigen::Vector3d position(frame.At(1).Number(), frame.At(2).Number(),
                             frame.At(3).Number());
    pose.root_position_m = to_world * position;
    pose.local_rotations.resize(skeleton->num_joints(),
                                Eigen::Quaterniond::Identity());
    pose.local_rotations[0] = to_world * ReadQuaternion(frame, 4) * from_world;
    size_t offset = 8;
    for (int j = 1; j < skeleton->num_joints(); ++j) {
      const SkeletonJoint& joint = skeleton->joints[j];
      if (joint.type == JointType::kSpherical) {
        pose.local_rotations[j] =
            to_world * ReadQuaternion(frame, offset) * from_world;
      } else if (joint.type == JointType::kRevolute) {
        // DeepMimic revolute joints turn about their z axis; in the world
        // convention that axis is the skeleton's `axis`.
        double angle = frame.At(offset).Number();
        pose.local_rotations[j] =
            Eigen::Quaterniond(Eigen::AngleAxisd(angle, joint.axis));
      }
      offset += ChannelCount(joint.type);
    }
    raw.frames.push_back(pose);
  }

  // DeepMimic frames carry their own durations; sample at a uniform rate.
  double source_fps = durations_s[0] > 0 ? 1.0 / durations_s[0] : 30.0;
  raw.fps = source_fps;
  bool uniform = true;
  for (size_t i = 0; i + 1 < num_frames; ++i) {
    if (!(durations_s[i] > 0)) {
      frames.At(i).Fail("non-positive frame duration");
    }
    uniform = uniform && std::abs(durations_s[i] - durations_s[0]) < 1e-6;
  }
  if (!uniform) {
    // Re-time on the true time stamps, then sample uniformly.
    Motion3D uniform_motion = raw;
    uniform_motion.frames.clear();
    double total = 0.0;
    for (size_t i = 0; i + 1 < num_frames; ++i) total += durations_s[i];
    double time = 0.0;
    size_t index = 0;
    for (int k = 0; k * (1.0 / source_fps) <= total + 1e-9; ++k) {
      double t = k / source_fps;
      while (index + 2 < num_frames && time + durations_s[index] < t) {
        time += durations_s[index];
        ++index;
      }
      double alpha = std::clamp((t - time) / durations_s[index], 0.0, 1.0);
      uniform_motion.frames.push_back(
          InterpolatePose(raw.frames[index], raw.frames[index + 1], alpha));
    }
    raw = uniform_motion;
  }
  if (fps > 0 && std::abs(fps - raw.fps) > 1e-9)
    return ResampleMotion(raw, fps);
  return raw;
}

}  // namespace m2d
