// Objects in bundles: a ball's 3D truth projected into every view, kept
// through files, validated; and its 3D recovered from one view's 2D.
#include "motion/object_track.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/file_io.h"
#include "motion/motion_io.h"
#include "synthetic_motion.h"
#include "test_paths.h"

namespace m2d {
namespace {

constexpr double kFps = 30.0;

struct GlidingWithBall {
  Motion3D motion;
  KeypointMap map;
  BundleFromMotionOptions options;
};

// The humanoid gliding 1 s along +x (31 frames), seen by 2 views.
GlidingWithBall Gliding() {
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(testing::SourcePath("assets/skeletons/humanoid.yaml")));
  GlidingWithBall out{
      testing::GlidingMotion(skeleton, testing::IdentityPose(*skeleton), 1.0),
      LoadKeypointMap(
          testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"),
          *skeleton),
      BundleFromMotionOptions()};
  out.options.rig.num_views = 2;
  return out;
}

void ExpectInputError(const ReferenceBundle& bundle,
                      const std::string& needle) {
  try {
    ValidateBundle(bundle, "b.json");
    ADD_FAILURE() << "expected InputError with " << needle;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("b.json"), std::string::npos) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  }
}

TEST(BundleObjects, AreProjectedIntoEveryViewAndKeptInTheTruth) {
  GlidingWithBall g = Gliding();
  const ObjectTrack3D ball = testing::RollingBallTrack(31, kFps);
  ReferenceBundle bundle =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding", {ball});
  ASSERT_EQ(bundle.ground_truth->objects.size(), 1u);
  EXPECT_EQ(bundle.ground_truth->objects[0].positions_m, ball.positions_m);
  for (const ReferenceView& view : bundle.views) {
    ASSERT_EQ(view.clip.objects.size(), 1u);
    EXPECT_EQ(view.clip.objects[0].name, "ball");
    for (int t = 0; t < 31; ++t) {
      const Keypoint2D& point = view.clip.objects[0].points[t];
      EXPECT_EQ(point.confidence, 1.0);
      EXPECT_LT((point.Pixel() -
                 view.CameraAt(t).Project(ball.positions_m[t]).pixel_px)
                    .norm(),
                1e-9);
    }
  }
  // The objects' 2D comes after the keypoints' noise: with objects, the
  // keypoints are the same noisy keypoints as without.
  g.options.noise.pixel_sigma_px = 3.0;
  g.options.noise.seed = 5;
  const ReferenceBundle plain =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding");
  const ReferenceBundle with_ball =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding", {ball});
  for (int t = 0; t < 31; ++t) {
    for (int j = 0; j < 17; ++j) {
      EXPECT_EQ(with_ball.views[1].clip.keypoints.at(t, j).Pixel(),
                plain.views[1].clip.keypoints.at(t, j).Pixel());
    }
  }
  // A track of another length is refused.
  ObjectTrack3D short_ball = ball;
  short_ball.positions_m.pop_back();
  EXPECT_THROW(
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding", {short_ball}),
      InputError);
}

TEST(BundleObjects, ABallOutsideTheImageIsNotDetected) {
  GlidingWithBall g = Gliding();
  g.options.rig.num_views = 1;
  // Rolling 30 m/s: out of every view within the second.
  const ObjectTrack3D ball =
      testing::RollingBallTrack(31, kFps, /*kick_s=*/0.2, /*speed=*/30.0);
  const ReferenceBundle bundle =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding", {ball});
  const Clip2D& clip = bundle.views[0].clip;
  EXPECT_EQ(clip.objects[0].points.front().confidence, 1.0);
  EXPECT_EQ(clip.objects[0].points.back().confidence, 0.0);
  for (const Keypoint2D& point : clip.objects[0].points) {
    const bool inside = point.x_px >= 0 && point.x_px < clip.image_width_px &&
                        point.y_px >= 0 && point.y_px < clip.image_height_px;
    EXPECT_EQ(point.confidence, inside ? 1.0 : 0.0);
  }
}

TEST(BundleObjects, RoundTripInTheTruthAndTheEstimate) {
  GlidingWithBall g = Gliding();
  ReferenceBundle bundle =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding",
                           {testing::RollingBallTrack(31, kFps)});
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{0.4, {1.0, 2.0, 0.0}}, {-1.1, {0.0, -3.0, 0.0}}});
  const std::string file = testing::TempDir("bundle_objects") + "/b.json";
  WriteBundle(file, bundle);
  const ReferenceBundle read = ReadBundle(file);
  ASSERT_EQ(read.ground_truth->objects.size(), 1u);
  EXPECT_EQ(read.ground_truth->objects[0].name, "ball");
  for (int t = 0; t < 31; ++t) {
    EXPECT_TRUE(read.ground_truth->objects[0].positions_m[t].isApprox(
        bundle.ground_truth->objects[0].positions_m[t], 1e-12));
    for (int k = 0; k < 2; ++k) {
      EXPECT_TRUE((*read.estimate)[k].objects[0].positions_m[t].isApprox(
          (*bundle.estimate)[k].objects[0].positions_m[t], 1e-12));
    }
  }
  // Bundles written before objects had 3D (no "objects" field) still read.
  nlohmann::json json = ReadJsonFile(file);
  json["ground_truth"].erase("objects");
  json["estimate"]["views"][0].erase("objects");
  WriteJsonFileAtomic(file, json);
  const ReferenceBundle old = ReadBundle(file);
  EXPECT_TRUE(old.ground_truth->objects.empty());
  EXPECT_TRUE((*old.estimate)[0].objects.empty());
}

TEST(BundleObjects, BadTracksNameTheFileAndTheObject) {
  GlidingWithBall g = Gliding();
  ReferenceBundle good =
      MakeBundleFromMotion(g.motion, g.map, g.options, "gliding",
                           {testing::RollingBallTrack(31, kFps)});
  good.estimate = testing::EstimateFromTruth(good, {{0.0, {0.0, 0.0, 0.0}}});
  EXPECT_NO_THROW(ValidateBundle(good, "b.json"));
  ReferenceBundle bad = good;
  bad.ground_truth->objects[0].positions_m.pop_back();
  ExpectInputError(bad, "ground truth object 'ball' has 30 positions");
  bad = good;
  bad.ground_truth->objects[0].name = "puck";
  ExpectInputError(bad, "ground truth object 'puck' has no 2D track");
  bad = good;
  bad.ground_truth->objects.push_back(bad.ground_truth->objects[0]);
  ExpectInputError(bad, "ground truth object 'ball' appears twice");
  bad = good;
  (*bad.estimate)[1].objects[0].positions_m[7].z() = std::nan("");
  ExpectInputError(bad, "estimate of view " + good.views[1].name +
                            " object 'ball': frame 7 is not finite");
}

TEST(PointOnHorizontalPlane, MeetsThePlaneInFrontOrNotAtAll) {
  const PinholeCamera camera =
      PinholeCamera::LookAt(Intrinsics(), {0.0, -5.0, 1.5}, {0.0, 0.0, 0.5});
  const Eigen::Vector3d ball(0.7, 0.4, 0.11);
  const auto found =
      PointOnHorizontalPlane(camera, camera.Project(ball).pixel_px, 0.11);
  ASSERT_TRUE(found.has_value());
  EXPECT_LT((*found - ball).norm(), 1e-9);
  // The image's top edge looks above the horizon: the plane is behind.
  EXPECT_FALSE(PointOnHorizontalPlane(camera, {960.0, 0.0}, 0.11));
}

TEST(RollingObjectFromPixels, RecoversARollingBallAndFillsWhatIsNotSeen) {
  const int num_frames = 31;
  const ObjectTrack3D truth = testing::RollingBallTrack(num_frames, kFps);
  const PinholeCamera camera =
      PinholeCamera::LookAt(Intrinsics(), {1.0, -6.0, 2.0}, {1.5, 0.0, 0.5});
  ObjectTrack2D track{"ball", {}};
  for (const Eigen::Vector3d& p : truth.positions_m) {
    const Projection projection = camera.Project(p);
    track.points.push_back(
        {projection.pixel_px.x(), projection.pixel_px.y(), 1.0});
  }
  // Missed at frames 0-1 (rests where first seen), 14-16 (rolling in
  // between: linear, exact), and from 25 on (left the image).
  for (int t : {0, 1, 14, 15, 16, 25, 26, 27, 28, 29, 30})
    track.points[t].confidence = 0.0;
  RollingBall ball;
  ball.deceleration_m_s2 = 0.5;
  const ObjectTrack3D found =
      RollingObjectFromPixels(track, {camera}, kFps, ball, "clip.json");
  EXPECT_EQ(found.name, "ball");
  ASSERT_EQ(found.positions_m.size(), static_cast<size_t>(num_frames));
  for (int t = 0; t < 25; ++t) {
    EXPECT_LT((found.positions_m[t] - truth.positions_m[t]).norm(), 1e-6)
        << "frame " << t;
  }
  // After frame 24 it rolls on at 3 m/s, slowing by 0.5 m/s^2.
  for (int t = 25; t < num_frames; ++t) {
    const double elapsed_s = (t - 24) / kFps;
    const double rolled_m = 3.0 * elapsed_s - 0.25 * elapsed_s * elapsed_s;
    EXPECT_NEAR(found.positions_m[t].x(), truth.positions_m[24].x() + rolled_m,
                1e-6);
    EXPECT_NEAR(found.positions_m[t].z(), 0.11, 1e-9);
  }
  // Never seen on the floor: a named error, never a made-up track.
  for (Keypoint2D& point : track.points) point.confidence = 0.0;
  try {
    RollingObjectFromPixels(track, {camera}, kFps, ball, "clip.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("clip.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("'ball' is not seen"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace m2d
