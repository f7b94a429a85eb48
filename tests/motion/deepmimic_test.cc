#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/file_io.h"
#include "motion/motion_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

std::shared_ptr<const Skeleton> Humanoid() {
  return std::make_shared<const Skeleton>(
      LoadSkeleton(testing::SourcePath("assets/skeletons/humanoid.yaml")));
}

TEST(Skeleton, HumanoidHas15JointsInDeepMimicOrder) {
  auto skeleton = Humanoid();
  ASSERT_EQ(skeleton->num_joints(), 15);
  EXPECT_EQ(skeleton->joints[0].type, JointType::kFree);
  EXPECT_EQ(skeleton->IndexOf("right_knee"), 4);
  EXPECT_EQ(skeleton->joints[4].type, JointType::kRevolute);
  KeypointMap map = LoadKeypointMap(
      testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"), *skeleton);
  EXPECT_EQ(map.anchors.size(), 17u);
}

TEST(DeepMimicReader, WalkIsZUpUprightAndLooping) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  auto skeleton = Humanoid();
  Motion3D motion = ReadDeepMimicMotion(path, skeleton);
  EXPECT_TRUE(motion.loops);
  EXPECT_NEAR(motion.fps, 30.0, 0.01);
  EXPECT_GE(motion.num_frames(), 38);
  KeypointMap map = LoadKeypointMap(
      testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"), *skeleton);
  for (const Pose3D& pose : motion.frames) {
    // Pelvis about 0.85 m above the floor; head above the pelvis; ankles
    // near the floor (Z up after the Y-up conversion).
    EXPECT_NEAR(pose.root_position_m.z(), 0.85, 0.1);
    std::vector<Eigen::Vector3d> k = KeypointPositions(*skeleton, map, pose);
    EXPECT_GT(k[static_cast<int>(Coco17::kNose)].z(),
              pose.root_position_m.z() + 0.5);
    EXPECT_LT(std::min(k[static_cast<int>(Coco17::kLeftAnkle)].z(),
                       k[static_cast<int>(Coco17::kRightAnkle)].z()),
              0.15);  // the stance foot
    // The subject's left hip is on its left: forward x left = up.
    Eigen::Vector3d left = k[static_cast<int>(Coco17::kLeftHip)] -
                           k[static_cast<int>(Coco17::kRightHip)];
    Eigen::Vector3d forward =
        pose.local_rotations[0] * Eigen::Vector3d::UnitX();
    EXPECT_GT(forward.cross(left).z(), 0.0);
  }
  // Walking moves forward along the facing direction.
  Eigen::Vector3d travel = motion.frames.back().root_position_m -
                           motion.frames.front().root_position_m;
  Eigen::Vector3d forward =
      motion.frames.front().local_rotations[0] * Eigen::Vector3d::UnitX();
  EXPECT_GT(travel.dot(forward), 0.5);
}

TEST(DeepMimicReader, ForwardKinematicsKeepsBoneLengths) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  auto skeleton = Humanoid();
  Motion3D motion = ReadDeepMimicMotion(path, skeleton);
  std::vector<Eigen::Vector3d> joints;
  for (const Pose3D& pose : motion.frames) {
    ForwardKinematics(*skeleton, pose, &joints);
    for (int j = 1; j < skeleton->num_joints(); ++j) {
      double length = (joints[j] - joints[skeleton->joints[j].parent]).norm();
      EXPECT_NEAR(length, skeleton->joints[j].offset_m.norm(), 1e-9);
    }
  }
}

TEST(DeepMimicReader, ExtendLoopContinuesWithoutJumps) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  auto skeleton = Humanoid();
  Motion3D motion = ReadDeepMimicMotion(path, skeleton);
  Motion3D looped = ExtendLoop(motion, 10.0);
  EXPECT_GE(looped.duration_s(), 10.0);
  auto max_step = [](const Motion3D& m) {
    double step = 0;
    for (int i = 1; i < m.num_frames(); ++i) {
      step = std::max(
          step, (m.frames[i].root_position_m - m.frames[i - 1].root_position_m)
                    .norm());
    }
    return step;
  };
  // No frame-to-frame jump larger than the clip's own largest step (plus a
  // little for the seam), and the walker keeps going: ~10 s of walking.
  EXPECT_LT(max_step(looped), 1.5 * max_step(motion));
  double distance = (looped.frames.back().root_position_m -
                     looped.frames.front().root_position_m)
                        .norm();
  EXPECT_GT(distance, 8.0);
}

// Largest frame-to-frame rotation (rad) of joint `j` between frames
// [begin, end).
double MaxJointStep(const Motion3D& motion, size_t j, int begin, int end) {
  double step = 0;
  for (int i = std::max(begin, 1); i < end; ++i) {
    step =
        std::max(step, motion.frames[i - 1].local_rotations[j].angularDistance(
                           motion.frames[i].local_rotations[j]));
  }
  return step;
}

TEST(DeepMimicReader, ExtendLoopClosesTheCycleSeam) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  Motion3D motion = ReadDeepMimicMotion(path, Humanoid());
  const int n = motion.num_frames();
  const size_t num_rotations = motion.frames[0].local_rotations.size();
  // The recorded cycle does not close: some joint's last frame is far from
  // its first (the right shoulder: 0.50 rad, twice its largest step).
  double worst_excess = 0;
  for (size_t j = 1; j < num_rotations; ++j) {
    const double seam = motion.frames[0].local_rotations[j].angularDistance(
        motion.frames[n - 1].local_rotations[j]);
    worst_excess = std::max(worst_excess, seam - MaxJointStep(motion, j, 1, n));
  }
  ASSERT_GT(worst_excess, 0.2);

  // Repeated, each joint steps no further across a seam than inside the
  // recorded cycle (the mismatch spread over 38 frames adds ~0.013 rad).
  Motion3D looped = ExtendLoop(motion, 10.0);
  for (size_t j = 0; j < num_rotations; ++j) {
    const double cycle_step = MaxJointStep(motion, j, 1, n);
    for (int seam = n - 1; seam + 1 < looped.num_frames(); seam += n - 1) {
      EXPECT_LT(MaxJointStep(looped, j, seam, seam + 2), cycle_step + 0.03)
          << "joint " << j << ", seam at frame " << seam;
    }
  }
  // The first frame is the recording's own.
  for (size_t j = 0; j < num_rotations; ++j) {
    EXPECT_TRUE(looped.frames[0].local_rotations[j].isApprox(
        motion.frames[0].local_rotations[j]));
  }
}

TEST(DeepMimicReader, AStraightLoopWalksAStraightLine) {
  // The walk cycle turns its heading a little each cycle; accumulated over
  // 20 s the walker goes round a wide circle. Straight, every cycle starts
  // with the first frame's heading, the path keeps to a line, and neither
  // the root nor its rotation jumps at a seam.
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  Motion3D motion = ReadDeepMimicMotion(path, Humanoid());
  const int n = motion.num_frames();
  auto heading_change_deg = [](const Pose3D& a, const Pose3D& b) {
    return std::abs(std::remainder(HeadingAngle(b.local_rotations[0]) -
                                       HeadingAngle(a.local_rotations[0]),
                                   2 * M_PI)) *
           180 / M_PI;
  };
  const Motion3D wrapped = ExtendLoop(motion, 20.0);
  EXPECT_GT(heading_change_deg(wrapped.frames.front(), wrapped.frames.back()),
            45.0);
  const Motion3D straight = ExtendLoop(motion, 20.0, LoopHeading::kStraight);
  ASSERT_EQ(straight.num_frames(), wrapped.num_frames());
  for (int seam = n - 1; seam < straight.num_frames(); seam += n - 1) {
    EXPECT_LT(
        heading_change_deg(straight.frames.front(), straight.frames[seam]), 1.0)
        << "cycle starting at frame " << seam;
  }
  // Lateral distance of the root from the line through its ends.
  const Eigen::Vector3d start = straight.frames.front().root_position_m;
  Eigen::Vector3d line = straight.frames.back().root_position_m - start;
  line.z() = 0.0;
  EXPECT_GT(line.norm(), 15.0);  // about 20 s of walking
  line.normalize();
  double widest_m = 0.0;
  for (const Pose3D& pose : straight.frames) {
    Eigen::Vector3d offset = pose.root_position_m - start;
    offset.z() = 0.0;
    widest_m = std::max(widest_m, (offset - offset.dot(line) * line).norm());
  }
  EXPECT_LT(widest_m, 0.2);
  const double root_turn_step = MaxJointStep(motion, 0, 1, n);
  for (int seam = n - 1; seam + 1 < straight.num_frames(); seam += n - 1)
    EXPECT_LT(MaxJointStep(straight, 0, seam, seam + 2), root_turn_step + 0.03);
  LoopHeading parsed = LoopHeading::kAccumulate;
  EXPECT_TRUE(ParseSetting("straight", &parsed));
  EXPECT_EQ(parsed, LoopHeading::kStraight);
  EXPECT_FALSE(ParseSetting("circle", &parsed));
}

TEST(DeepMimicReader, ResampleKeepsSpanAndEndpoints) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  Motion3D motion = ReadDeepMimicMotion(path, Humanoid());
  Motion3D fast = ResampleMotion(motion, 120.0);
  EXPECT_NEAR(fast.duration_s(), motion.duration_s(), 1.0 / 120.0);
  EXPECT_TRUE(fast.frames.front().root_position_m.isApprox(
      motion.frames.front().root_position_m));
  EXPECT_TRUE(fast.frames[4].root_position_m.isApprox(
      motion.frames[1].root_position_m, 1e-3));
}

void ExpectMotionError(const std::string& text, const std::string& needle) {
  std::string dir = testing::TempDir("deepmimic_bad");
  std::string path = dir + "/bad.txt";
  std::ofstream(path) << text;
  try {
    ReadDeepMimicMotion(path, Humanoid());
    FAIL() << "expected InputError for " << text.substr(0, 60);
  } catch (const InputError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  }
}

TEST(DeepMimicReader, BadFilesNameTheFileAndTheProblem) {
  std::string good_frame = "[0.0333, 0, 0.85, 0, 1, 0, 0, 0";
  std::string joints;
  for (int j = 0; j < 8; ++j) joints += ", 1, 0, 0, 0";  // 8 spherical
  for (int j = 0; j < 4; ++j) joints += ", 0.1";         // 4 revolute
  ExpectMotionError("{\"Loop\": \"wrap\", \"Frames\": [", "malformed JSON");
  ExpectMotionError("{\"Loop\": \"wrap\"}", "missing field 'Frames'");
  ExpectMotionError("{\"Frames\": []}", "no frames");
  ExpectMotionError("{\"Frames\": [" + good_frame + joints + ", 7]]}",
                    "has 45 values, skeleton 'humanoid' needs 44");
  ExpectMotionError("{\"Frames\": [" + good_frame +
                        joints.substr(0, joints.size() - 5) + ", null]]}",
                    "Frames[0][43]: expected a number");
  ExpectMotionError(
      "{\"Frames\": [[0.0333, 0, 0.85, 0, 0, 0, 0, 0" + joints + "]]}",
      "zero-length quaternion");
  ExpectMotionError("", "malformed JSON");
}

// Found by fuzzing: "Wrap" (capitalized) was read as not looping.
TEST(DeepMimicReader, LoopIsReadWithoutCase) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  std::string text = ReadFileText(path);
  const size_t at = text.find("\"wrap\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 6, "\"Wrap\"");
  const std::string dir = testing::TempDir("deepmimic_loop");
  const std::string copy = dir + "/walk.txt";
  WriteFileAtomic(copy, text);
  EXPECT_TRUE(ReadDeepMimicMotion(copy, Humanoid()).loops);
}

TEST(DeepMimicReader, MissingFileIsAnInputError) {
  try {
    ReadDeepMimicMotion("/nonexistent/walk.txt", Humanoid());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/walk.txt"),
              std::string::npos);
  }
}

TEST(Skeleton, BadSkeletonFilesAreInputErrors) {
  std::string dir = testing::TempDir("skeleton_bad");
  std::string path = dir + "/s.yaml";
  std::ofstream(path)
      << "name: x\njoints:\n  - {name: root, type: free, offset_m: [0, 0, 0]}\n"
         "  - {name: a, parent: nope, type: spherical, offset_m: [0, 0, 1]}\n";
  EXPECT_THROW(LoadSkeleton(path), InputError);
  std::ofstream(path) << "name: x\njoints:\n  - {name: root, type: wobbly, "
                         "offset_m: [0, 0, 0]}\n";
  EXPECT_THROW(LoadSkeleton(path), InputError);
  std::ofstream(path) << "name: x\njoints: [\n";
  EXPECT_THROW(LoadSkeleton(path), InputError);
  std::string map_path = dir + "/m.yaml";
  std::ofstream(map_path) << "layout: coco17\nkeypoints:\n  snout: {joint: "
                             "neck, offset_m: [0, 0, 0]}\n";
  EXPECT_THROW(LoadKeypointMap(map_path, *Humanoid()), InputError);
  std::ofstream(map_path) << "layout: coco99\nkeypoints: {}\n";
  EXPECT_THROW(LoadKeypointMap(map_path, *Humanoid()), InputError);
}

}  // namespace
}  // namespace m2d
