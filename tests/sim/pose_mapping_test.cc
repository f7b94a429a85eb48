// tests: Pose3D <-> qpos for a character: Euler decomposition, MuJoCo's
// hinge composition, keypoint sites against the skeleton FK on DeepMimic
// motion, and finite-difference velocities.
#include "sim/pose_mapping.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "motion/motion_io.h"
#include "sim_test_util.h"

namespace m2d {
namespace {

using testing::LoadHumanoid;

Eigen::Quaterniond RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  return q.normalized();
}

double RotationDistance(const Eigen::Quaterniond& a,
                        const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

TEST(PoseMappingTest, IntrinsicXyzAnglesRoundTripOnBothBranches) {
  std::mt19937 rng(3);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Quaterniond q = RandomRotation(&rng);
    const Eigen::Vector3d angles = IntrinsicXyzAngles(q);
    EXPECT_LE(std::abs(angles[1]), M_PI / 2 + 1e-12);
    EXPECT_LT(RotationDistance(FromIntrinsicXyzAngles(angles), q), 1e-9);
    EXPECT_LT(
        RotationDistance(FromIntrinsicXyzAngles(AlternateXyzAngles(angles)), q),
        1e-9);
  }
  // Gimbal lock: b = +-90 degrees.
  const Eigen::Quaterniond locked =
      FromIntrinsicXyzAngles({0.3, M_PI / 2, -0.2});
  EXPECT_LT(RotationDistance(FromIntrinsicXyzAngles(IntrinsicXyzAngles(locked)),
                             locked),
            1e-9);
}

// MuJoCo composes a body's hinges in declaration order, so the chest's
// abdomen_x, _y, _z give R = Rx Ry Rz: check against mj_kinematics.
TEST(PoseMappingTest, MujocoComposesHingesAsIntrinsicXyz) {
  auto character = LoadHumanoid("floating");
  const mjModel* m = character->model();
  MujocoDataPtr data = MakeMujocoData(m);
  const int chest = character->skeleton().IndexOf("chest");
  const BoundJoint& bound = character->joints()[chest];
  const Eigen::Vector3d angles(0.3, -0.5, 0.8);
  for (int k = 0; k < 3; ++k) {
    data->qpos[character->hinges()[bound.first_hinge + k].qpos_address] =
        angles[k];
  }
  mj_kinematics(m, data.get());
  const double* xquat = data->xquat + 4 * bound.body_id;
  const Eigen::Quaterniond mujoco(xquat[0], xquat[1], xquat[2], xquat[3]);
  EXPECT_LT(RotationDistance(mujoco, FromIntrinsicXyzAngles(angles)), 1e-12);
  // Not the extrinsic order.
  const Eigen::Quaterniond zyx =
      Eigen::AngleAxisd(angles[2], Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(angles[1], Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(angles[0], Eigen::Vector3d::UnitX());
  EXPECT_GT(RotationDistance(mujoco, zyx), 0.1);
}

// A random pose within the joint ranges: spherical joints as Euler angles
// in range, revolute joints as signed skeleton-axis angles in range.
Pose3D RandomPose(const Character& character, std::mt19937* rng) {
  const Skeleton& skeleton = character.skeleton();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto in_range = [&](const ActuatedHinge& h) {
    return h.range_low_rad + unit(*rng) * (h.range_high_rad - h.range_low_rad);
  };
  Pose3D pose;
  pose.root_position_m =
      Eigen::Vector3d(unit(*rng), unit(*rng), 0.5 + unit(*rng));
  pose.local_rotations.assign(skeleton.num_joints(),
                              Eigen::Quaterniond::Identity());
  pose.local_rotations[0] = RandomRotation(rng);
  for (int j = 1; j < skeleton.num_joints(); ++j) {
    const BoundJoint& bound = character.joints()[j];
    if (bound.type == JointType::kSpherical) {
      Eigen::Vector3d angles;
      for (int k = 0; k < 3; ++k)
        angles[k] = in_range(character.hinges()[bound.first_hinge + k]);
      pose.local_rotations[j] = FromIntrinsicXyzAngles(angles);
    } else if (bound.type == JointType::kRevolute) {
      const double angle = in_range(character.hinges()[bound.first_hinge]);
      pose.local_rotations[j] = Eigen::AngleAxisd(bound.revolute_sign * angle,
                                                  skeleton.joints[j].axis);
    }
  }
  return pose;
}

double MaxKeypointGap(const Character& character, mjData* data,
                      const Pose3D& pose) {
  PoseToQpos(character, pose, data->qpos);
  mj_kinematics(character.model(), data);
  const std::vector<Eigen::Vector3d> expected =
      KeypointPositions(character.skeleton(), character.keypoint_map(), pose);
  double worst = 0.0;
  for (size_t k = 0; k < expected.size(); ++k) {
    const Eigen::Vector3d site(data->site_xpos +
                               3 * character.keypoint_sites()[k]);
    worst = std::max(worst, (site - expected[k]).norm());
  }
  return worst;
}

// For the humanoid and the dog: their MJCF sites are their skeletons'
// keypoints, whatever the pose.
TEST(PoseMappingTest, QposRoundTripAndSitesMatchSkeletonFkOnRandomPoses) {
  for (auto character : {LoadHumanoid("floating"), testing::LoadDog("flat")}) {
    SCOPED_TRACE(character->name());
    MujocoDataPtr data = MakeMujocoData(character->model());
    std::mt19937 rng(11);
    for (int i = 0; i < 200; ++i) {
      const Pose3D pose = RandomPose(*character, &rng);
      EXPECT_LT(MaxKeypointGap(*character, data.get(), pose), 1e-9);
      const Pose3D back = QposToPose(*character, data->qpos);
      EXPECT_LT((back.root_position_m - pose.root_position_m).norm(), 1e-12);
      for (size_t j = 0; j < pose.local_rotations.size(); ++j) {
        EXPECT_LT(
            RotationDistance(back.local_rotations[j], pose.local_rotations[j]),
            1e-9)
            << character->skeleton().joints[j].name;
      }
    }
  }
}

TEST(PoseMappingTest, SpheresPickTheEulerBranchInsideTheRanges) {
  // A right shoulder raised forward past horizontal (-150 degrees about y):
  // the principal Euler solution (180, -30, 180) is out of range; the other
  // one (0, -150, 0) is inside it.
  auto character = LoadHumanoid("floating");
  Pose3D pose = QposToPose(*character, character->model()->qpos0);
  const int shoulder = character->skeleton().IndexOf("right_shoulder");
  pose.local_rotations[shoulder] =
      Eigen::AngleAxisd(-150.0 * M_PI / 180.0, Eigen::Vector3d::UnitY());
  std::vector<double> qpos(character->model()->qpos0,
                           character->model()->qpos0 + character->model()->nq);
  PoseToQpos(*character, pose, qpos.data());
  const int first = character->joints()[shoulder].first_hinge;
  EXPECT_NEAR(qpos[character->hinges()[first].qpos_address], 0.0, 1e-9);
  EXPECT_NEAR(qpos[character->hinges()[first + 1].qpos_address],
              -150.0 * M_PI / 180.0, 1e-9);
  EXPECT_NEAR(qpos[character->hinges()[first + 2].qpos_address], 0.0, 1e-9);
}

// The DeepMimic format maps exactly onto the character: replaying a clip
// kinematically puts every keypoint site where the skeleton FK puts it.
TEST(PoseMappingTest, DeepMimicWalkSitesMatchSkeletonKeypointsWithin1mm) {
  M2D_REQUIRE_SHARED(walk_path, "deepmimic/motions/humanoid3d_walk.txt");
  auto character = LoadHumanoid("flat");
  const Motion3D motion =
      ReadDeepMimicMotion(walk_path, character->shared_skeleton());
  ASSERT_GT(motion.num_frames(), 10);
  MujocoDataPtr data = MakeMujocoData(character->model());
  double worst = 0.0;
  for (const Pose3D& pose : motion.frames) {
    worst = std::max(worst, MaxKeypointGap(*character, data.get(), pose));
  }
  EXPECT_LT(worst, 1e-3) << "over " << motion.num_frames() << " frames";
  std::printf("walk: %d frames, largest site-to-FK keypoint gap %.3g m\n",
              motion.num_frames(), worst);
}

// Converted frame by frame, the kick's and the dance's ball joints switch
// between their two Euler solutions (steps of 3.10 and 3.15 rad with no
// motion); along the clip they do not (at most 1.21 and 0.44 rad), and
// every frame keeps its rotations.
TEST(PoseMappingTest, AlongAClipBallJointsKeepTheirEulerSolution) {
  auto character = LoadHumanoid("flat");
  const int nq = character->model()->nq;
  for (const char* clip : {"kick", "dance_a"}) {
    M2D_REQUIRE_SHARED(
        path, std::string("deepmimic/motions/humanoid3d_") + clip + ".txt");
    const Motion3D motion =
        ReadDeepMimicMotion(path, character->shared_skeleton());
    // The largest step of any hinge between frames (rad).
    auto largest_step = [&](const std::vector<std::vector<double>>& rows) {
      double largest = 0.0;
      for (size_t t = 1; t < rows.size(); ++t) {
        for (const ActuatedHinge& hinge : character->hinges()) {
          largest =
              std::max(largest, std::abs(rows[t][hinge.qpos_address] -
                                         rows[t - 1][hinge.qpos_address]));
        }
      }
      return largest;
    };
    std::vector<std::vector<double>> per_frame(motion.num_frames(),
                                               std::vector<double>(nq, 0.0));
    for (int t = 0; t < motion.num_frames(); ++t)
      PoseToQpos(*character, motion.frames[t], per_frame[t].data());
    const std::vector<std::vector<double>> along =
        PosesToQposAlongClip(*character, motion.frames);
    std::printf(
        "%s: largest hinge step %.2f rad frame by frame, %.2f along "
        "the clip\n",
        clip, largest_step(per_frame), largest_step(along));
    EXPECT_GT(largest_step(per_frame), 2.0) << clip;
    EXPECT_LT(largest_step(along), 1.5) << clip;  // measured 1.21, 0.44
    ASSERT_EQ(along.size(), motion.frames.size());
    for (int t = 0; t < motion.num_frames(); ++t) {
      const Pose3D back = QposToPose(*character, along[t].data());
      for (size_t j = 0; j < back.local_rotations.size(); ++j) {
        ASSERT_LT(RotationDistance(back.local_rotations[j],
                                   motion.frames[t].local_rotations[j]),
                  1e-9)
            << clip << " frame " << t << " joint "
            << character->skeleton().joints[j].name;
      }
    }
  }
}

// qvel from two poses, integrated by MuJoCo over dt, reaches the second
// pose: the root's angular velocity is in the root frame as MuJoCo expects.
TEST(PoseMappingTest, FiniteDifferenceQvelIntegratesToTheNextPose) {
  M2D_REQUIRE_SHARED(run_path, "deepmimic/motions/humanoid3d_run.txt");
  auto character = LoadHumanoid("flat");
  const mjModel* m = character->model();
  const Motion3D motion =
      ReadDeepMimicMotion(run_path, character->shared_skeleton());
  const double dt = 1.0 / motion.fps;
  std::vector<double> qpos_a(m->nq), qpos_b(m->nq), qvel(m->nv);
  for (int i = 0; i + 1 < motion.num_frames(); ++i) {
    PoseToQpos(*character, motion.frames[i], qpos_a.data());
    QvelFromPoses(*character, motion.frames[i], motion.frames[i + 1], dt,
                  qvel.data());
    mj_integratePos(m, qpos_a.data(), qvel.data(), dt);
    const Pose3D reached = QposToPose(*character, qpos_a.data());
    const Pose3D& target = motion.frames[i + 1];
    EXPECT_LT((reached.root_position_m - target.root_position_m).norm(), 1e-9);
    for (size_t j = 0; j < target.local_rotations.size(); ++j) {
      ASSERT_LT(RotationDistance(reached.local_rotations[j],
                                 target.local_rotations[j]),
                1e-6)
          << "frame " << i << " joint " << character->skeleton().joints[j].name;
    }
  }
}

}  // namespace
}  // namespace m2d
