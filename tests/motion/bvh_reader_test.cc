#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/error.h"
#include "motion/motion3d.h"
#include "motion/motion_io.h"
#include "motion/skeleton.h"
#include "test_paths.h"

namespace m2d {
namespace {

using Eigen::Vector3d;

// The CMU capture Debian ships with assimp's test models (package
// assimp-testmodels): subject 1, trial 1, 2752 frames at 120 Hz.
constexpr char kCmuBvhPath[] = "/usr/share/assimp/models/BVH/01_01.bvh";
// cgspeed's conversion writes lengths in inches / 0.45.
constexpr double kCmuScaleM = 0.056444;

#define REQUIRE_CMU_BVH()                                            \
  if (!std::filesystem::exists(kCmuBvhPath)) {                       \
    GTEST_FAIL() << kCmuBvhPath                                      \
                 << " is absent (Debian package assimp-testmodels, " \
                    "installed by setup.sh)";                        \
  }

std::vector<Vector3d> JointPositions(const Motion3D& motion, int frame) {
  std::vector<Vector3d> positions;
  ForwardKinematics(*motion.skeleton, motion.frames[frame], &positions);
  return positions;
}

int JointIndex(const Skeleton& skeleton, const std::string& name) {
  const int index = skeleton.IndexOf(name);
  EXPECT_GE(index, 0) << "joint " << name << " missing";
  return index;
}

// Writes `contents` to a file in this test's temp folder.
std::string WriteTempFile(const std::string& name,
                          const std::string& contents) {
  const std::string path = testing::TempDir("bvh_reader") + "/" + name;
  std::ofstream(path) << contents;
  return path;
}

// Two joints and an end site; the root rotates Z, X, Y in that order.
const char kTinyHierarchy[] =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "  OFFSET 0 0 0\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
    "Yrotation\n"
    "  JOINT Chest\n"
    "  {\n"
    "    OFFSET 0 10 0\n"
    "    CHANNELS 3 Zrotation Xrotation Yrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 5 0\n"
    "    }\n"
    "  }\n"
    "}\n";

std::string TinyBvh(const std::string& motion_section) {
  return std::string(kTinyHierarchy) + motion_section;
}

const char kTinyMotion[] =
    "MOTION\n"
    "Frames: 3\n"
    "Frame Time: 0.1\n"
    "0 20 0 0 0 0 0 0 0\n"
    "1 20 2 90 0 0 0 0 0\n"
    "1 20 2 90 90 0 0 90 0\n";

// Reads `contents` as a BVH file and returns the InputError's message.
std::string ReadErrorOf(const std::string& contents, double scale_m = 0.01) {
  const std::string path = WriteTempFile("bad.bvh", contents);
  try {
    ReadBvhMotion(path, scale_m);
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path);
    return error.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << contents;
  return "";
}

TEST(BvhReaderTest, TinyFileMatchesHandComputedKinematics) {
  const std::string path = WriteTempFile("tiny.bvh", TinyBvh(kTinyMotion));
  const Motion3D motion = ReadBvhMotion(path, 0.01);

  const Skeleton& skeleton = *motion.skeleton;
  EXPECT_EQ(skeleton.name, "tiny");
  ASSERT_EQ(skeleton.num_joints(), 3);
  EXPECT_EQ(skeleton.joints[0].name, "Hips");
  EXPECT_EQ(skeleton.joints[0].type, JointType::kFree);
  EXPECT_EQ(skeleton.joints[1].name, "Chest");
  EXPECT_EQ(skeleton.joints[1].type, JointType::kSpherical);
  EXPECT_EQ(skeleton.joints[1].parent, 0);
  EXPECT_EQ(skeleton.joints[2].name, "Chest_end");
  EXPECT_EQ(skeleton.joints[2].type, JointType::kFixed);
  EXPECT_EQ(skeleton.joints[2].parent, 1);
  // File (0, 10, 0) Y-up, in cm -> world (0, 0, 0.1) Z-up, in m.
  EXPECT_TRUE(skeleton.joints[1].offset_m.isApprox(Vector3d(0, 0, 0.1)));
  EXPECT_TRUE(skeleton.joints[2].offset_m.isApprox(Vector3d(0, 0, 0.05)));

  EXPECT_DOUBLE_EQ(motion.fps, 10.0);
  EXPECT_FALSE(motion.loops);
  ASSERT_EQ(motion.num_frames(), 3);

  // Hand-computed in the file frame (Y up), BVH order v' = Rz Rx Ry v,
  // then (x, y, z) -> (x, -z, y) and cm -> m:
  // frame 0: rest pose standing on the root at height 20.
  // frame 1: root turned 90° about z: Chest (-9, 20, 2), end (-14, 20, 2).
  // frame 2: root Rz90·Rx90 puts Chest at (1, 20, 12); Chest's extra Rx90
  //          gives it Rz90·Rx180, sending the end site to (6, 20, 12).
  const std::vector<std::vector<Vector3d>> expected = {
      {{0, 0, 0.20}, {0, 0, 0.30}, {0, 0, 0.35}},
      {{0.01, -0.02, 0.20}, {-0.09, -0.02, 0.20}, {-0.14, -0.02, 0.20}},
      {{0.01, -0.02, 0.20}, {0.01, -0.12, 0.20}, {0.06, -0.12, 0.20}},
  };
  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<Vector3d> positions = JointPositions(motion, frame);
    for (int joint = 0; joint < 3; ++joint) {
      EXPECT_LT((positions[joint] - expected[frame][joint]).norm(), 1e-6)
          << "frame " << frame << " joint " << skeleton.joints[joint].name
          << ": " << positions[joint].transpose();
    }
  }
  // A turn about the file's x axis is a turn about the world's x axis.
  const Eigen::Quaterniond chest = motion.frames[2].local_rotations[1];
  EXPECT_LT(chest.angularDistance(Eigen::Quaterniond(
                Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX()))),
            1e-6);
}

TEST(BvhReaderTest, RequestedFpsResamplesTheMotion) {
  const std::string path = WriteTempFile("tiny.bvh", TinyBvh(kTinyMotion));
  const Motion3D motion = ReadBvhMotion(path, 0.01, 20.0);
  EXPECT_DOUBLE_EQ(motion.fps, 20.0);
  ASSERT_EQ(motion.num_frames(), 5);  // 0.2 s at 20 Hz
  // Frame 1 (t = 0.05 s) lies halfway between file frames 0 and 1.
  EXPECT_TRUE(
      motion.frames[1].root_position_m.isApprox(Vector3d(0.005, -0.01, 0.20)));
}

TEST(BvhReaderTest, FrameLinesBeyondTheDeclaredCountAreIgnored) {
  // Some exporters write one frame more than they declare (Debian's
  // Boxing_Toes.bvh); assimp and other readers keep the declared count.
  const std::string path =
      WriteTempFile("extra.bvh", TinyBvh("MOTION\nFrames: 2\nFrame Time: 0.1\n"
                                         "0 20 0 0 0 0 0 0 0\n"
                                         "1 20 2 90 0 0 0 0 0\n"
                                         "1 20 2 90 90 0 0 90 0\n"));
  EXPECT_EQ(ReadBvhMotion(path, 0.01).num_frames(), 2);
}

TEST(BvhReaderTest, DebianBoxingCaptureKeepsItsDeclaredFrames) {
  const std::string path = "/usr/share/assimp/models/BVH/Boxing_Toes.bvh";
  if (!std::filesystem::exists(path)) {
    GTEST_FAIL() << path
                 << " is absent (assimp-testmodels, installed by setup.sh)";
  }
  // 3070 frame lines under "Frames: 3069", rotations in Z X Y order.
  const Motion3D motion = ReadBvhMotion(path, 0.01);
  EXPECT_EQ(motion.num_frames(), 3069);
  EXPECT_DOUBLE_EQ(motion.fps, 100.0);
  EXPECT_EQ(motion.skeleton->joints[0].name, "Hips");
  EXPECT_GE(motion.skeleton->IndexOf("Head_end"), 0);
}

TEST(BvhReaderTest, ConstantPositionChannelsOnAJointBecomeItsOffset) {
  // Exporters such as MotionBuilder give every joint 6 channels whose
  // positions repeat the offset; they replace the OFFSET line.
  const std::string contents =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
      "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n"
      "  JOINT Chest\n  {\n    OFFSET 0 99 0\n"
      "    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n"
      "    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n"
      "MOTION\nFrames: 2\nFrame Time: 0.1\n"
      "0 20 0 0 0 0 0 10 0 0 0 0\n"
      "0 20 0 0 0 0 0 10 0 0 0 0\n";
  const Motion3D motion =
      ReadBvhMotion(WriteTempFile("six.bvh", contents), 0.01);
  EXPECT_TRUE(
      motion.skeleton->joints[1].offset_m.isApprox(Vector3d(0, 0, 0.1)));
}

TEST(BvhReaderTest, CmuCaptureFrameCountAndRate) {
  REQUIRE_CMU_BVH();
  const Motion3D motion = ReadBvhMotion(kCmuBvhPath, kCmuScaleM);
  EXPECT_EQ(motion.num_frames(), 2752);
  EXPECT_DOUBLE_EQ(motion.fps, 120.0);  // "Frame Time: .0083333"
  EXPECT_FALSE(motion.loops);
  EXPECT_EQ(motion.skeleton->name, "01_01");
}

TEST(BvhReaderTest, CmuCaptureSkeletonHasHipsRootAndMappedJoints) {
  REQUIRE_CMU_BVH();
  const Motion3D motion = ReadBvhMotion(kCmuBvhPath, kCmuScaleM);
  const Skeleton& skeleton = *motion.skeleton;
  EXPECT_EQ(skeleton.joints[0].name, "Hips");
  EXPECT_EQ(skeleton.joints[0].type, JointType::kFree);
  // 31 joints with channels and 7 end sites (toes, head, fingers, thumbs).
  EXPECT_EQ(skeleton.num_joints(), 38);
  for (const char* name :
       {"Head", "LeftArm", "RightArm", "LeftForeArm", "RightForeArm",
        "LeftHand", "RightHand", "LeftUpLeg", "RightUpLeg", "LeftLeg",
        "RightLeg", "LeftFoot", "RightFoot"}) {
    const int joint = JointIndex(skeleton, name);
    if (joint >= 0) {
      EXPECT_EQ(skeleton.joints[joint].type, JointType::kSpherical);
    }
  }
  const int head_end = JointIndex(skeleton, "Head_end");
  ASSERT_GE(head_end, 0);
  EXPECT_EQ(skeleton.joints[head_end].type, JointType::kFixed);
  EXPECT_EQ(skeleton.joints[head_end].parent, skeleton.IndexOf("Head"));
  // The CMU rest pose stands upright: the head end sits above the hips.
  EXPECT_GT(skeleton.joints[skeleton.IndexOf("Neck1")].offset_m.z(), 0.0);
}

TEST(BvhReaderTest, CmuCaptureStandingHeightIsHuman) {
  REQUIRE_CMU_BVH();
  const Motion3D motion = ReadBvhMotion(kCmuBvhPath, kCmuScaleM);
  const Skeleton& skeleton = *motion.skeleton;
  const std::vector<Vector3d> positions = JointPositions(motion, 0);
  // Frame 0 stands still. Stature runs from the top of the head (the Head
  // joint's end site; the Head joint itself sits ~0.1 m lower, near the
  // mouth) down to the lowest point of either foot chain.
  double lowest_foot_z_m = std::numeric_limits<double>::infinity();
  for (const char* name : {"LeftFoot", "LeftToeBase", "LeftToeBase_end",
                           "RightFoot", "RightToeBase", "RightToeBase_end"}) {
    lowest_foot_z_m =
        std::min(lowest_foot_z_m, positions[JointIndex(skeleton, name)].z());
  }
  const double height_m =
      positions[JointIndex(skeleton, "Head_end")].z() - lowest_foot_z_m;
  EXPECT_GT(height_m, 1.4);
  EXPECT_LT(height_m, 1.9);
  // The hips sit a bit over half way up.
  const double hips_z_m = positions[0].z() - lowest_foot_z_m;
  EXPECT_GT(hips_z_m / height_m, 0.5);
  EXPECT_LT(hips_z_m / height_m, 0.7);
}

TEST(BvhReaderTest, CmuCaptureLimbLengthsStayConstant) {
  REQUIRE_CMU_BVH();
  const Motion3D motion = ReadBvhMotion(kCmuBvhPath, kCmuScaleM);
  const Skeleton& skeleton = *motion.skeleton;
  const std::vector<Vector3d> first = JointPositions(motion, 0);
  for (int frame = 1; frame < motion.num_frames(); frame += 97) {
    const std::vector<Vector3d> positions = JointPositions(motion, frame);
    for (int j = 1; j < skeleton.num_joints(); ++j) {
      const int parent = skeleton.joints[j].parent;
      const double length_m = (positions[j] - positions[parent]).norm();
      EXPECT_NEAR(length_m, (first[j] - first[parent]).norm(), 1e-9)
          << skeleton.joints[j].name << " frame " << frame;
      EXPECT_NEAR(length_m, skeleton.joints[j].offset_m.norm(), 1e-9);
    }
  }
}

TEST(BvhReaderTest, CmuKeypointMapPutsTheNoseInFrontOfTheHead) {
  REQUIRE_CMU_BVH();
  const Motion3D motion = ReadBvhMotion(kCmuBvhPath, kCmuScaleM);
  const Skeleton& skeleton = *motion.skeleton;
  const KeypointMap map = LoadKeypointMap(
      testing::SourcePath("assets/skeletons/cmu_bvh.coco17.yaml"), skeleton);
  ASSERT_EQ(map.anchors.size(), 17u);
  const int head = JointIndex(skeleton, "Head");
  const auto index = [](Coco17 keypoint) { return static_cast<int>(keypoint); };
  int frames = 0;
  int frames_facing_ahead = 0;
  for (int frame = 0; frame < motion.num_frames(); frame += 10) {
    const std::vector<Vector3d> keypoints =
        KeypointPositions(skeleton, map, motion.frames[frame]);
    const std::vector<Vector3d> joints = JointPositions(motion, frame);
    // Left is +y when facing +x with +z up, so facing = left × up.
    const Vector3d hips_left_m = keypoints[index(Coco17::kLeftHip)] -
                                 keypoints[index(Coco17::kRightHip)];
    const Vector3d facing = hips_left_m.cross(Vector3d::UnitZ()).normalized();
    const double nose_ahead_m =
        (keypoints[index(Coco17::kNose)] - joints[head]).dot(facing);
    // The subject turns around mid-clip with the head leading the hips, so
    // the nose is always ahead but only usually by its full 0.1 m.
    EXPECT_GT(nose_ahead_m, 0.0) << "frame " << frame;
    if (nose_ahead_m > 0.08) ++frames_facing_ahead;
    ++frames;
    // The left eye and ear are on the hips' left.
    EXPECT_GT((keypoints[index(Coco17::kLeftEye)] -
               keypoints[index(Coco17::kRightEye)])
                  .dot(hips_left_m),
              0.0)
        << "frame " << frame;
    EXPECT_GT((keypoints[index(Coco17::kLeftEar)] -
               keypoints[index(Coco17::kRightEar)])
                  .dot(hips_left_m),
              0.0)
        << "frame " << frame;
  }
  EXPECT_GT(frames_facing_ahead, 0.9 * frames);
}

TEST(BvhReaderTest, MissingFileIsAnInputError) {
  const std::string path = testing::TempDir("bvh_reader") + "/absent.bvh";
  try {
    ReadBvhMotion(path, 0.01);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path);
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
  }
}

TEST(BvhReaderTest, NonBvhFileIsAnInputError) {
  EXPECT_NE(ReadErrorOf("{\"Loop\": \"wrap\", \"Frames\": []}\n")
                .find("not a BVH file"),
            std::string::npos);
  EXPECT_NE(ReadErrorOf("").find("not a BVH file"), std::string::npos);
}

TEST(BvhReaderTest, TruncatedHierarchyIsAnInputError) {
  const std::string hierarchy = kTinyHierarchy;
  // Cut in the middle of the Chest's OFFSET line: no MOTION follows.
  const std::string cut = hierarchy.substr(0, hierarchy.find("10 0") + 2);
  EXPECT_NE(ReadErrorOf(cut).find("no MOTION section"), std::string::npos);
  // A hierarchy missing its closing braces is caught by assimp.
  const std::string unclosed =
      hierarchy.substr(0, hierarchy.rfind("}\n}")) +
      "MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0 0 0 0\n";
  EXPECT_NE(ReadErrorOf(unclosed).find("BVH import failed: line"),
            std::string::npos);
}

TEST(BvhReaderTest, FrameWithMissingChannelValuesIsAnInputError) {
  // Assimp would silently read frame 1's missing value from frame 2's line.
  const std::string error =
      ReadErrorOf(TinyBvh("MOTION\nFrames: 3\nFrame Time: 0.1\n"
                          "0 20 0 0 0 0 0 0 0\n"
                          "1 20 2 90 0 0 0 0\n"
                          "1 20 2 90 90 0 0 90 0 0\n"));
  EXPECT_NE(error.find("line 20 (frame 1) has 8 values but the hierarchy "
                       "declares 9 channels"),
            std::string::npos)
      << error;
  // Fewer frame lines than declared.
  EXPECT_NE(ReadErrorOf(TinyBvh("MOTION\nFrames: 4\nFrame Time: 0.1\n"
                                "0 20 0 0 0 0 0 0 0\n"))
                .find("only 1 frame lines"),
            std::string::npos);
  // A short line among extra frame lines is still an error.
  EXPECT_NE(ReadErrorOf(TinyBvh("MOTION\nFrames: 1\nFrame Time: 0.1\n"
                                "0 20 0 0 0 0 0 0 0\n"
                                "0 20 0 0 0 0 0\n"))
                .find("(frame 1) has 7 values"),
            std::string::npos);
}

TEST(BvhReaderTest, ZeroFramesIsAnInputError) {
  EXPECT_NE(ReadErrorOf(TinyBvh("MOTION\nFrames: 0\nFrame Time: 0.1\n"))
                .find("no frames"),
            std::string::npos);
}

TEST(BvhReaderTest, NonPositiveFrameTimeIsAnInputError) {
  EXPECT_NE(ReadErrorOf(TinyBvh("MOTION\nFrames: 1\nFrame Time: 0\n"
                                "0 20 0 0 0 0 0 0 0\n"))
                .find("Frame Time must be positive"),
            std::string::npos);
}

TEST(BvhReaderTest, NanValuesAreAnInputError) {
  const std::string rotation_error =
      ReadErrorOf(TinyBvh("MOTION\nFrames: 2\nFrame Time: 0.1\n"
                          "0 20 0 0 0 0 0 0 0\n"
                          "0 20 0 0 0 0 0 nan 0\n"));
  EXPECT_NE(rotation_error.find("frame 1: joint 'Chest' has NaN"),
            std::string::npos)
      << rotation_error;
  const std::string position_error =
      ReadErrorOf(TinyBvh("MOTION\nFrames: 1\nFrame Time: 0.1\n"
                          "0 inf 0 0 0 0 0 0 0\n"));
  EXPECT_NE(position_error.find("frame 0: root position is NaN"),
            std::string::npos)
      << position_error;
  std::string hierarchy = kTinyHierarchy;
  hierarchy.replace(hierarchy.find("0 10 0"), 6, "0 nan 0");
  EXPECT_NE(ReadErrorOf(hierarchy + kTinyMotion)
                .find("joint 'Chest' has a non-finite OFFSET"),
            std::string::npos);
}

TEST(BvhReaderTest, NonPositiveScaleIsAnInputError) {
  const std::string contents = TinyBvh(kTinyMotion);
  for (double scale_m :
       {0.0, -0.01, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_NE(ReadErrorOf(contents, scale_m).find("scale must be a positive"),
              std::string::npos)
        << scale_m;
  }
}

TEST(BvhReaderTest, PositionChannelsAssimpWouldDropAreAnInputError) {
  // Assimp reads positions only from 6-channel joints; a 3-channel
  // position-only root would silently stand still.
  std::string hierarchy = kTinyHierarchy;
  hierarchy.replace(hierarchy.find("CHANNELS 6"), std::string::npos,
                    "CHANNELS 3 Xposition Yposition Zposition\n"
                    "  JOINT Chest\n  {\n    OFFSET 0 10 0\n"
                    "    CHANNELS 3 Zrotation Xrotation Yrotation\n"
                    "    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n");
  EXPECT_NE(ReadErrorOf(hierarchy + "MOTION\nFrames: 1\nFrame Time: 0.1\n"
                                    "0 20 0 0 0 0\n")
                .find("declares 3 channels including positions"),
            std::string::npos);
}

TEST(BvhReaderTest, AnimatedNonRootPositionsAreAnInputError) {
  const std::string contents =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
      "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n"
      "  JOINT Chest\n  {\n    OFFSET 0 10 0\n"
      "    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n"
      "    End Site\n    {\n      OFFSET 0 5 0\n    }\n  }\n}\n"
      "MOTION\nFrames: 2\nFrame Time: 0.1\n"
      "0 20 0 0 0 0 0 10 0 0 0 0\n"
      "0 20 0 0 0 0 0 12 0 0 0 0\n";
  EXPECT_NE(ReadErrorOf(contents).find("joint 'Chest' has animated position"),
            std::string::npos);
}

}  // namespace
}  // namespace m2d
