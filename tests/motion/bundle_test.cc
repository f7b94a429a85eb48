#include "motion/bundle.h"

#include <gtest/gtest.h>

#include "common/error.h"
#include "motion/motion_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

struct WalkFixture {
  Motion3D motion;
  KeypointMap map;
};

WalkFixture LoadWalk(const std::string& path) {
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(testing::SourcePath("assets/skeletons/humanoid.yaml")));
  return {ReadDeepMimicMotion(path, skeleton),
          LoadKeypointMap(
              testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"),
              *skeleton)};
}

// Largest distance between each view's 2D points and the projection of the
// ground-truth 3D keypoints through that view's camera.
double MaxReprojectionGap(const ReferenceBundle& bundle) {
  double gap = 0.0;
  for (const ReferenceView& view : bundle.views) {
    for (int t = 0; t < bundle.num_frames(); ++t) {
      for (int j = 0; j < view.clip.keypoints.num_keypoints(); ++j) {
        const Keypoint2D& k = view.clip.keypoints.at(t, j);
        if (!k.IsPresent()) continue;
        Projection p =
            view.CameraAt(t).Project(bundle.ground_truth->keypoints_m[t][j]);
        gap = std::max(gap, (p.pixel_px - k.Pixel()).norm());
      }
    }
  }
  return gap;
}

TEST(Bundle, FourViewWalkEqualsProjectionOfItsGroundTruthAfterRoundTrip) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions options;
  options.rig.num_views = 4;
  ReferenceBundle bundle =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  ASSERT_EQ(bundle.views.size(), 4u);
  ASSERT_TRUE(bundle.ground_truth.has_value());
  EXPECT_EQ(bundle.ground_truth->poses.size(),
            static_cast<size_t>(bundle.num_frames()));

  std::string file = testing::TempDir("bundle") + "/walk.json";
  WriteBundle(file, bundle);
  ReferenceBundle read = ReadBundle(file);
  ASSERT_EQ(read.views.size(), 4u);
  ASSERT_EQ(read.num_frames(), bundle.num_frames());
  EXPECT_LT(MaxReprojectionGap(read), 1e-6);
  // Every keypoint is visible and the subject fills a sensible part of the
  // 1080 px image from 4.5 m with f = 1000 px (~1.6 m tall -> ~350 px).
  for (const ViewSummary& view : SummarizeBundle(read)) {
    EXPECT_DOUBLE_EQ(view.present_fraction, 1.0);
    EXPECT_DOUBLE_EQ(view.in_image_fraction, 1.0);
    EXPECT_NEAR(view.mean_height_px, 350, 80) << view.name;
  }
}

TEST(Bundle, LoopedFollowedWalkStaysInFrame) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions options;
  options.duration_s = 10.0;
  options.follow = CameraFollow::kRootDolly;
  ReferenceBundle bundle =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  EXPECT_EQ(bundle.num_frames(), 301);
  EXPECT_EQ(bundle.views[0].cameras.size(), 301u);
  EXPECT_LT(MaxReprojectionGap(bundle), 1e-6);
  for (const ViewSummary& view : SummarizeBundle(bundle)) {
    EXPECT_DOUBLE_EQ(view.in_image_fraction, 1.0) << view.name;
  }
}

TEST(Bundle, DetectorNoiseIsSeededAndHasTheRequestedStatistics) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions clean_options;
  clean_options.duration_s = 10.0;
  clean_options.follow = CameraFollow::kRootDolly;  // keep the walker in view
  ReferenceBundle clean =
      MakeBundleFromMotion(walk.motion, walk.map, clean_options, "walk");
  BundleFromMotionOptions options = clean_options;
  options.noise.pixel_sigma_px = 3.0;
  options.noise.drop_probability = 0.1;
  options.noise.seed = 42;
  ReferenceBundle noisy =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  ReferenceBundle again =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");

  double sum_sq = 0.0;
  long present = 0, total = 0;
  for (size_t k = 0; k < noisy.views.size(); ++k) {
    for (int t = 0; t < noisy.num_frames(); ++t) {
      for (int j = 0; j < 17; ++j) {
        const Keypoint2D& a = noisy.views[k].clip.keypoints.at(t, j);
        const Keypoint2D& b = again.views[k].clip.keypoints.at(t, j);
        ++total;
        EXPECT_EQ(a.IsPresent(), b.IsPresent());
        if (!a.IsPresent()) continue;
        EXPECT_EQ(a.x_px, b.x_px);
        ++present;
        Eigen::Vector2d d =
            a.Pixel() - clean.views[k].clip.keypoints.at(t, j).Pixel();
        sum_sq += d.squaredNorm();
      }
    }
  }
  double drop_rate = 1.0 - static_cast<double>(present) / total;
  EXPECT_NEAR(drop_rate, 0.1, 0.02);
  EXPECT_NEAR(std::sqrt(sum_sq / (2.0 * present)), 3.0, 0.15);
}

TEST(Bundle, InconsistentBundlesAreRejected) {
  ReferenceBundle bundle;
  bundle.name = "x";
  EXPECT_THROW(ValidateBundle(bundle, "x.json"), InputError);
  ReferenceView view;
  view.name = "a";
  view.cameras.resize(1);
  view.clip.keypoints = KeypointTrack(5, 17);
  bundle.views.push_back(view);
  view.name = "b";
  view.clip.keypoints = KeypointTrack(4, 17);
  bundle.views.push_back(view);
  try {
    ValidateBundle(bundle, "x.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("view b has 4 frames"),
              std::string::npos)
        << e.what();
  }
  bundle.views.pop_back();
  bundle.views[0].cameras.resize(3);
  EXPECT_THROW(ValidateBundle(bundle, "x.json"), InputError);
}

TEST(Bundle, BadOptionsAreConfigErrors) {
  BundleFromMotionOptions options;
  options.noise.drop_probability = 1.5;
  EXPECT_THROW(options.Validate(), ConfigError);
  options = BundleFromMotionOptions();
  options.fps = 0;
  EXPECT_THROW(options.Validate(), ConfigError);
}

}  // namespace
}  // namespace m2d
