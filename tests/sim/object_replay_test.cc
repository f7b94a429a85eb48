// A ball moved by a kick replayed on the humanoid: where the ball goes and
// that only the motion's contact moves it.
#include "sim/object_replay.h"

#include <gtest/gtest.h>

#include "common/error.h"
#include "motion/motion_io.h"
#include "sim_test_util.h"

namespace m2d {
namespace {

// DeepMimic's kick (in the repository, MIT) at the bundle's 30 fps.
Motion3D Kick(const Character& character) {
  const Motion3D motion = ReadDeepMimicMotion(
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_kick.txt"),
      character.shared_skeleton());
  return SampleMotionForBundle(motion, BundleFromMotionOptions());
}

TEST(ObjectReplay, TheBallSceneKnowsItsBallsRadius) {
  auto character = testing::LoadHumanoid("ball");
  ASSERT_EQ(character->free_objects().size(), 1u);
  EXPECT_EQ(character->free_objects()[0].name, "ball");
  EXPECT_DOUBLE_EQ(character->free_objects()[0].radius_m, 0.11);
}

TEST(ObjectReplay, AKickSendsTheBallItWasPutInFrontOf) {
  auto character = testing::LoadHumanoid("ball");
  const Motion3D kick = Kick(*character);
  const BallPlacement placement = PlaceBallInFootPath(*character, kick, 0.11);
  // The right foot's kick, about half a second in.
  EXPECT_EQ(placement.foot_body, character->BodyId("right_foot"));
  EXPECT_GE(placement.frame, 10);
  EXPECT_LE(placement.frame, 18);
  EXPECT_GT(placement.foot_speed_m_s, 3.0);
  EXPECT_DOUBLE_EQ(placement.center_m.z(), 0.11);

  const std::vector<ObjectTrack3D> tracks =
      ReplayObjectsAlongMotion(*character, kick, {placement.center_m});
  ASSERT_EQ(tracks.size(), 1u);
  EXPECT_EQ(tracks[0].name, "ball");
  const std::vector<Eigen::Vector3d>& path = tracks[0].positions_m;
  ASSERT_EQ(path.size(), static_cast<size_t>(kick.num_frames()));
  // At rest until the foot arrives (settled on the floor within 5 mm),
  // then sent forward (+x, the way the kick goes) by metres, never through
  // the floor.
  for (int t = 0; t < placement.frame - 2; ++t) {
    EXPECT_LT((path[t] - placement.center_m).norm(), 0.005) << "frame " << t;
  }
  EXPECT_GT(path.back().x() - placement.center_m.x(), 2.0);
  for (const Eigen::Vector3d& p : path) EXPECT_GT(p.z(), 0.1);
}

TEST(ObjectReplay, ABallOutOfReachStaysPut) {
  auto character = testing::LoadHumanoid("ball");
  const Motion3D kick = Kick(*character);
  const Eigen::Vector3d far(5.0, 5.0, 0.11);
  const std::vector<ObjectTrack3D> tracks =
      ReplayObjectsAlongMotion(*character, kick, {far});
  for (const Eigen::Vector3d& p : tracks[0].positions_m)
    EXPECT_LT((p - far).norm(), 0.005);
}

TEST(ObjectReplay, MismatchedInputsAreNamedErrors) {
  auto character = testing::LoadHumanoid("ball");
  Motion3D kick = Kick(*character);
  EXPECT_THROW(ReplayObjectsAlongMotion(*character, kick, {}), InputError);
  // 25 fps is not a whole number of 120 Hz steps.
  kick.fps = 25.0;
  try {
    ReplayObjectsAlongMotion(*character, kick, {{1.0, 0.0, 0.11}});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a whole number of physics"),
              std::string::npos)
        << e.what();
  }
  // A motion that never brings a foot near the floor has nowhere to kick.
  Motion3D flying = Kick(*character);
  for (Pose3D& pose : flying.frames) pose.root_position_m.z() += 2.0;
  EXPECT_THROW(PlaceBallInFootPath(*character, flying, 0.11), InputError);
}

}  // namespace
}  // namespace m2d
