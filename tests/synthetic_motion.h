// tests: motions and bundles made here, without the shared data — a pose
// carried forward at walking speed with a swinging joint, a quadruped's
// trot, and a synthetic `mimic2d fit` estimate (the truth seen in another
// world frame).
#ifndef MIMIC2D_TESTS_SYNTHETIC_MOTION_H_
#define MIMIC2D_TESTS_SYNTHETIC_MOTION_H_

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "motion/bundle.h"
#include "motion/motion3d.h"
#include "motion/skeleton.h"

namespace m2d::testing {

// `standing` carried along +x at `speed_m_s`, the last joint swinging by
// 0.3 rad at 1 Hz about its parent's x axis, sampled at `fps`.
inline Motion3D GlidingMotion(std::shared_ptr<const Skeleton> skeleton,
                              const Pose3D& standing, double duration_s,
                              double fps = 30.0, double speed_m_s = 0.5) {
  Motion3D motion;
  motion.skeleton = std::move(skeleton);
  motion.fps = fps;
  const int num_frames = static_cast<int>(std::round(duration_s * fps)) + 1;
  for (int t = 0; t < num_frames; ++t) {
    Pose3D pose = standing;
    const double time_s = t / fps;
    pose.root_position_m.x() += speed_m_s * time_s;
    Eigen::Quaterniond& last = pose.local_rotations.back();
    last = last *
           Eigen::Quaterniond(Eigen::AngleAxisd(
               0.3 * std::sin(2 * M_PI * time_s), Eigen::Vector3d::UnitX()));
    motion.frames.push_back(pose);
  }
  return motion;
}

// The identity pose of `skeleton` with its root `height_m` above the floor.
inline Pose3D IdentityPose(const Skeleton& skeleton, double height_m = 0.9) {
  Pose3D pose;
  pose.root_position_m = {0.0, 0.0, height_m};
  pose.local_rotations.assign(skeleton.num_joints(),
                              Eigen::Quaterniond::Identity());
  return pose;
}

// A trot of the dog skeleton (assets/skeletons/dog.yaml) along +x at
// `speed_m_s`, 2 strides a second: diagonal legs swing together (hips and
// shoulders +-0.35 rad about y), each elbow or knee bending further while
// its leg swings forward, the spine and head bobbing a little. Each frame's
// root is lifted or lowered until its lowest paw keypoint is 2 cm up (the
// paw's sole on the floor). Made here so that the dog's tests run without
// the dog3d clips, which stay in ../shared.
inline Motion3D SyntheticTrot(std::shared_ptr<const Skeleton> skeleton,
                              const KeypointMap& keypoint_map,
                              double duration_s, double fps = 30.0,
                              double speed_m_s = 1.0) {
  Motion3D motion;
  motion.fps = fps;
  const int num_frames = static_cast<int>(std::round(duration_s * fps)) + 1;
  auto about_y = [](double angle_rad) {
    return Eigen::Quaterniond(
        Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitY()));
  };
  // Legs: (swinging joint, bending joint, bend sign, phase).
  struct Leg {
    const char* hip;
    const char* knee;
    double bend_sign;
    double phase_rad;
  };
  const Leg legs[] = {{"left_shoulder", "left_forearm", 1.0, 0.0},
                      {"right_upper_leg", "right_leg", -1.0, 0.0},
                      {"right_shoulder", "right_forearm", 1.0, M_PI},
                      {"left_upper_leg", "left_leg", -1.0, M_PI}};
  std::vector<int> paws;
  for (const char* paw :
       {"left_front_paw", "right_front_paw", "left_back_paw", "right_back_paw"})
    paws.push_back(keypoint_map.layout->IndexOf(paw));
  for (int t = 0; t < num_frames; ++t) {
    const double time_s = t / fps;
    const double stride_rad = 2 * M_PI * 2.0 * time_s;
    Pose3D pose;
    pose.root_position_m = {speed_m_s * time_s, 0.0, 0.0};
    pose.local_rotations.assign(skeleton->num_joints(),
                                Eigen::Quaterniond::Identity());
    for (const Leg& leg : legs) {
      const double swing = std::sin(stride_rad + leg.phase_rad);
      // Positive y turns a hanging leg backward: forward swing is -y.
      pose.local_rotations[skeleton->IndexOf(leg.hip)] = about_y(-0.35 * swing);
      const double bend =
          0.3 + 0.5 * std::max(0.0, std::cos(stride_rad + leg.phase_rad));
      // A revolute joint turns about its skeleton axis (-y for both).
      pose.local_rotations[skeleton->IndexOf(leg.knee)] =
          Eigen::Quaterniond(Eigen::AngleAxisd(
              leg.bend_sign * bend,
              skeleton->joints[skeleton->IndexOf(leg.knee)].axis));
    }
    pose.local_rotations[skeleton->IndexOf("spine1")] =
        about_y(0.05 * std::sin(2 * stride_rad));
    // The head held up, snout forward (its rest snout points down).
    pose.local_rotations[skeleton->IndexOf("head")] =
        about_y(-1.2 + 0.1 * std::sin(2 * stride_rad));
    const std::vector<Eigen::Vector3d> points =
        KeypointPositions(*skeleton, keypoint_map, pose);
    double lowest_m = 1e9;
    for (int paw : paws) lowest_m = std::min(lowest_m, points[paw].z());
    pose.root_position_m.z() += 0.02 - lowest_m;
    motion.frames.push_back(pose);
  }
  motion.skeleton = std::move(skeleton);
  return motion;
}

// A ball of `radius_m` resting at (x0, y0) until `kick_s`, then rolling
// along +x at `speed_m_s` (no slowing), sampled at `fps` for `num_frames`.
inline ObjectTrack3D RollingBallTrack(int num_frames, double fps,
                                      double kick_s = 0.3,
                                      double speed_m_s = 3.0,
                                      double radius_m = 0.11, double x0_m = 0.5,
                                      double y0_m = 0.2) {
  ObjectTrack3D ball{"ball", {}};
  for (int t = 0; t < num_frames; ++t) {
    const double rolled_m = speed_m_s * std::max(0.0, t / fps - kick_s);
    ball.positions_m.emplace_back(x0_m + rolled_m, y0_m, radius_m);
  }
  return ball;
}

// The world moved by p' = R(yaw) p + shift (a rotation about z and a
// horizontal shift): the same physical scene in another world frame.
struct WorldChange {
  double yaw_rad = 0.0;
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();

  Eigen::Matrix3d rotation() const {
    return Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())
        .toRotationMatrix();
  }
  Eigen::Vector3d Point(const Eigen::Vector3d& p) const {
    return rotation() * p + shift_m;
  }
  Pose3D Pose(Pose3D pose) const {
    pose.root_position_m = Point(pose.root_position_m);
    pose.local_rotations[0] =
        Eigen::Quaterniond(rotation()) * pose.local_rotations[0];
    return pose;
  }
  // The camera that sees the moved world as `camera` saw the original.
  PinholeCamera Camera(const PinholeCamera& camera) const {
    const Eigen::Matrix3d r =
        camera.rotation_world_to_camera() * rotation().transpose();
    return PinholeCamera(camera.intrinsics(), r,
                         camera.translation_m() - r * shift_m);
  }
};

// An estimate of every view made from `bundle`'s truth and true cameras
// (and objects): view k seen in the world moved by `changes[k]` (so each
// view has its own frame, as `mimic2d fit` gives).
inline std::vector<ViewEstimate> EstimateFromTruth(
    const ReferenceBundle& bundle, const std::vector<WorldChange>& changes) {
  std::vector<ViewEstimate> estimate;
  for (size_t k = 0; k < bundle.views.size(); ++k) {
    const WorldChange& change = changes[k % changes.size()];
    ViewEstimate view;
    for (const PinholeCamera& camera : bundle.views[k].cameras)
      view.cameras.push_back(change.Camera(camera));
    view.skeleton_name = bundle.ground_truth->skeleton_name;
    for (const Pose3D& pose : bundle.ground_truth->poses)
      view.poses.push_back(change.Pose(pose));
    for (const ObjectTrack3D& object : bundle.ground_truth->objects) {
      ObjectTrack3D moved{object.name, {}};
      for (const Eigen::Vector3d& p : object.positions_m)
        moved.positions_m.push_back(change.Point(p));
      view.objects.push_back(std::move(moved));
    }
    view.residual_px.assign(bundle.num_frames(), 0.5);
    view.summary.camera_model =
        bundle.views[k].cameras.size() == 1 ? "static" : "moving";
    view.summary.initialization = "synthetic";
    view.summary.num_frames = bundle.num_frames();
    view.summary.iterations = 12;
    view.summary.initial_cost = 100.0;
    view.summary.final_cost = 1.5;
    view.summary.mean_reprojection_px = 0.5;
    view.summary.seconds = 0.25;
    estimate.push_back(std::move(view));
  }
  return estimate;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_SYNTHETIC_MOTION_H_
