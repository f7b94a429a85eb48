#include "motion/bundle.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/file_io.h"
#include "motion/clip_io.h"
#include "motion/motion_io.h"
#include "synthetic_motion.h"
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

// A following camera keeps pace with a subject moving steadily, to the
// clip's ends: on a 1-s walk under the 1-s smoothing window it travels as
// far as the walker and never stalls. (Its window once shrank on one side
// only: such a clip was followed at half speed, then not at all, then at
// half speed.)
TEST(Bundle, AFollowingCameraKeepsPaceToTheClipsEnds) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions options;
  options.duration_s = 1.0;
  options.rig.num_views = 1;
  options.follow = CameraFollow::kRootDolly;
  ReferenceBundle bundle =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  const std::vector<Pose3D>& poses = bundle.ground_truth->poses;
  const int last = bundle.num_frames() - 1;
  const double walked_m =
      (poses[last].root_position_m - poses[0].root_position_m).head<2>().norm();
  ASSERT_GT(walked_m, 0.5);
  const ReferenceView& view = bundle.views[0];
  auto centre = [&](int t) { return view.CameraAt(t).CenterWorld(); };
  EXPECT_NEAR((centre(last) - centre(0)).head<2>().norm(), walked_m,
              0.05 * walked_m);
  for (int t = 0; t < last; ++t) {
    EXPECT_GT((centre(t + 1) - centre(t)).norm(), 0.5 * walked_m / last)
        << "frame " << t;
  }
}

// Static cameras aimed midway along the path: a walker starts as far
// before the rig's target as it ends past it.
TEST(Bundle, AimingAtThePathsMiddleCentresATravellingSubject) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions options;
  options.duration_s = 3.0;
  options.rig.num_views = 1;
  options.rig.first_azimuth_deg = 90;  // looking along -y at the target
  options.aim = RigAim::kPathMiddle;
  ReferenceBundle bundle =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  const std::vector<Pose3D>& poses = bundle.ground_truth->poses;
  const Eigen::Vector3d start = poses.front().root_position_m;
  const Eigen::Vector3d end = poses.back().root_position_m;
  ASSERT_GT((end - start).head<2>().norm(), 2.0);  // it travels
  Eigen::Vector3d centre = bundle.views[0].CameraAt(0).CenterWorld();
  Eigen::Vector3d middle = 0.5 * (start + end);
  EXPECT_NEAR(centre.x(), middle.x(), 1e-9);
  EXPECT_NEAR(centre.y() - options.rig.distance_m *
                               std::cos(options.rig.elevation_deg * M_PI / 180),
              middle.y(), 1e-9);
  // From the start root instead, the camera stands beside the first frame.
  options.aim = RigAim::kStartRoot;
  centre = MakeBundleFromMotion(walk.motion, walk.map, options, "walk")
               .views[0]
               .CameraAt(0)
               .CenterWorld();
  EXPECT_NEAR(centre.x(), start.x(), 1e-9);
}

// A user with one video has a clip, not a bundle: `fit` reads it as a
// one-view bundle named after the file; a bundle file reads as before.
TEST(Bundle, AClipFileReadsAsAOneViewBundle) {
  M2D_REQUIRE_SHARED(path, "deepmimic/motions/humanoid3d_walk.txt");
  WalkFixture walk = LoadWalk(path);
  BundleFromMotionOptions options;
  options.rig.num_views = 2;
  ReferenceBundle bundle =
      MakeBundleFromMotion(walk.motion, walk.map, options, "walk");
  const std::string dir = testing::TempDir("bundle_or_clip");
  WriteClip(dir + "/my_video.json", bundle.views[1].clip);
  WriteBundle(dir + "/walk_bundle.json", bundle);
  ReferenceBundle from_clip = ReadBundleOrClip(dir + "/my_video.json");
  EXPECT_EQ(from_clip.name, "my_video");
  ASSERT_EQ(from_clip.views.size(), 1u);
  EXPECT_TRUE(from_clip.views[0].cameras.empty());
  EXPECT_FALSE(from_clip.ground_truth.has_value());
  EXPECT_DOUBLE_EQ(from_clip.fps, bundle.fps);
  EXPECT_EQ(from_clip.num_frames(), bundle.num_frames());
  EXPECT_EQ(ReadBundleOrClip(dir + "/walk_bundle.json").views.size(), 2u);
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

// Without the shared data: the skeleton's identity pose gliding forward,
// seen by 2 views, with a synthetic estimate of each view.
ReferenceBundle GlidingBundleWithEstimate() {
  auto skeleton = std::make_shared<const Skeleton>(
      LoadSkeleton(testing::SourcePath("assets/skeletons/humanoid.yaml")));
  KeypointMap map = LoadKeypointMap(
      testing::SourcePath("assets/skeletons/humanoid.coco17.yaml"), *skeleton);
  BundleFromMotionOptions options;
  options.rig.num_views = 2;
  ReferenceBundle bundle = MakeBundleFromMotion(
      testing::GlidingMotion(skeleton, testing::IdentityPose(*skeleton), 1.0),
      map, options, "gliding");
  bundle.estimate = testing::EstimateFromTruth(
      bundle, {{0.4, {1.0, 2.0, 0.0}}, {-1.1, {0.0, -3.0, 0.0}}});
  (*bundle.estimate)[1].summary.unconverged_frames = {3, 17};
  return bundle;
}

TEST(Bundle, Version2RoundTripsTheEstimate) {
  ReferenceBundle bundle = GlidingBundleWithEstimate();
  const std::string file = testing::TempDir("bundle_v2") + "/gliding.json";
  WriteBundle(file, bundle);
  EXPECT_EQ(ReadJsonFile(file)["version"], 2);
  ReferenceBundle read = ReadBundle(file);
  ASSERT_TRUE(read.estimate.has_value());
  ASSERT_EQ(read.estimate->size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    const ViewEstimate& a = (*bundle.estimate)[k];
    const ViewEstimate& b = (*read.estimate)[k];
    ASSERT_EQ(b.cameras.size(), a.cameras.size());
    EXPECT_TRUE(b.cameras[0].rotation_world_to_camera().isApprox(
        a.cameras[0].rotation_world_to_camera(), 1e-12));
    EXPECT_TRUE(b.cameras[0].translation_m().isApprox(
        a.cameras[0].translation_m(), 1e-12));
    EXPECT_EQ(b.skeleton_name, a.skeleton_name);
    ASSERT_EQ(b.poses.size(), a.poses.size());
    for (size_t t = 0; t < a.poses.size(); ++t) {
      EXPECT_TRUE(
          b.poses[t].root_position_m.isApprox(a.poses[t].root_position_m));
      for (size_t j = 0; j < a.poses[t].local_rotations.size(); ++j) {
        EXPECT_TRUE(b.poses[t].local_rotations[j].isApprox(
            a.poses[t].local_rotations[j], 1e-12));
      }
    }
    EXPECT_EQ(b.residual_px, a.residual_px);
    EXPECT_EQ(b.summary.camera_model, a.summary.camera_model);
    EXPECT_EQ(b.summary.focal_fixed, a.summary.focal_fixed);
    EXPECT_EQ(b.summary.initialization, a.summary.initialization);
    EXPECT_EQ(b.summary.num_frames, a.summary.num_frames);
    EXPECT_EQ(b.summary.iterations, a.summary.iterations);
    EXPECT_EQ(b.summary.initial_cost, a.summary.initial_cost);
    EXPECT_EQ(b.summary.final_cost, a.summary.final_cost);
    EXPECT_EQ(b.summary.mean_reprojection_px, a.summary.mean_reprojection_px);
    EXPECT_EQ(b.summary.unconverged_frames, a.summary.unconverged_frames);
    EXPECT_EQ(b.summary.seconds, a.summary.seconds);
  }
  // Views fitted alone, each in its own world, unless the file says one.
  EXPECT_FALSE(read.estimate_one_world);
  bundle.estimate_one_world = true;
  WriteBundle(file, bundle);
  EXPECT_TRUE(ReadBundle(file).estimate_one_world);
  EXPECT_FALSE(StripBundle(bundle).estimate_one_world);
  // A file whose estimate names views out of order is rejected.
  nlohmann::json json = ReadJsonFile(file);
  std::swap(json["estimate"]["views"][0], json["estimate"]["views"][1]);
  WriteJsonFileAtomic(file, json);
  try {
    ReadBundle(file);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("one per view, in order"),
              std::string::npos)
        << e.what();
  }
}

TEST(Bundle, Version1FilesStillLoad) {
  ReferenceBundle bundle = GlidingBundleWithEstimate();
  bundle.estimate.reset();
  const std::string file = testing::TempDir("bundle_v1") + "/gliding.json";
  WriteBundle(file, bundle);
  nlohmann::json json = ReadJsonFile(file);
  json["version"] = 1;
  WriteJsonFileAtomic(file, json);
  ReferenceBundle read = ReadBundle(file);
  EXPECT_EQ(read.views.size(), 2u);
  EXPECT_TRUE(read.ground_truth.has_value());
  EXPECT_FALSE(read.estimate.has_value());
  EXPECT_EQ(read.views[0].cameras.size(), 1u);
  json["version"] = 3;
  WriteJsonFileAtomic(file, json);
  EXPECT_THROW(ReadBundle(file), InputError);
}

TEST(Bundle, StripKeepsOnlyThe2D) {
  ReferenceBundle bundle = GlidingBundleWithEstimate();
  ReferenceBundle stripped = StripBundle(bundle);
  EXPECT_FALSE(stripped.ground_truth.has_value());
  EXPECT_FALSE(stripped.estimate.has_value());
  EXPECT_EQ(stripped.name, bundle.name);
  EXPECT_EQ(stripped.fps, bundle.fps);
  ASSERT_EQ(stripped.views.size(), bundle.views.size());
  for (size_t k = 0; k < bundle.views.size(); ++k) {
    const Clip2D& a = bundle.views[k].clip;
    const Clip2D& b = stripped.views[k].clip;
    EXPECT_TRUE(stripped.views[k].cameras.empty());
    EXPECT_EQ(stripped.views[k].name, bundle.views[k].name);
    EXPECT_EQ(b.image_width_px, a.image_width_px);
    EXPECT_EQ(b.image_height_px, a.image_height_px);
    EXPECT_EQ(b.fps, a.fps);
    for (int t = 0; t < a.num_frames(); ++t) {
      for (int j = 0; j < 17; ++j)
        EXPECT_EQ(b.keypoints.at(t, j).Pixel(), a.keypoints.at(t, j).Pixel());
    }
  }
  // A stripped bundle (views without cameras) is written and read back.
  const std::string file = testing::TempDir("bundle_strip") + "/s.json";
  WriteBundle(file, stripped);
  EXPECT_TRUE(ReadBundle(file).views[1].cameras.empty());
}

TEST(Bundle, BadEstimatesNameTheFileAndTheView) {
  const ReferenceBundle good = GlidingBundleWithEstimate();
  auto expect_error = [](const ReferenceBundle& bundle,
                         const std::string& needle) {
    try {
      ValidateBundle(bundle, "g.json");
      ADD_FAILURE() << "expected InputError with " << needle;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("g.json"), std::string::npos) << message;
      EXPECT_NE(message.find(needle), std::string::npos) << message;
    }
  };
  const std::string view1 = "estimate of view " + good.views[1].name;
  ReferenceBundle bad = good;
  bad.estimate->pop_back();
  expect_error(bad, "estimate has 1 views");
  bad = good;
  (*bad.estimate)[1].poses.pop_back();
  expect_error(
      bad, view1 + " has " + std::to_string(good.num_frames() - 1) + " poses");
  bad = good;
  (*bad.estimate)[1].residual_px.push_back(1.0);
  expect_error(bad, view1 + " has " + std::to_string(good.num_frames() + 1) +
                        " residuals");
  bad = good;
  (*bad.estimate)[1].cameras.resize(2, (*bad.estimate)[1].cameras[0]);
  expect_error(bad, view1 + " has 2 cameras");
  bad = good;
  (*bad.estimate)[1].poses[4].root_position_m.x() = std::nan("");
  expect_error(bad, view1 + ": frame 4");
  bad = good;
  (*bad.estimate)[0].residual_px[2] = INFINITY;
  expect_error(bad, "frame 2 has a non-finite");
  EXPECT_NO_THROW(ValidateBundle(good, "g.json"));
}

TEST(FitSummary, BriefReportListsTheFramesThatFailed) {
  FitSummary summary;
  summary.camera_model = "moving";
  summary.focal_fixed = true;
  summary.initialization = "facing 180 deg";
  summary.num_frames = 300;
  summary.iterations = 42;
  summary.initial_cost = 1234.5;
  summary.final_cost = 12.25;
  summary.mean_reprojection_px = 3.5;
  summary.seconds = 7.25;
  std::string report = summary.BriefReport();
  for (const char* needle :
       {"camera moving", "focal fixed", "facing 180 deg", "42 iterations",
        "1234.5", "12.25", "3.50 px", "7.2 s", "all frames converged"}) {
    EXPECT_NE(report.find(needle), std::string::npos) << needle << "\n"
                                                      << report;
  }
  for (int t = 0; t < 12; ++t) summary.unconverged_frames.push_back(10 + t);
  summary.focal_fixed = false;
  report = summary.BriefReport();
  EXPECT_NE(report.find("focal estimated"), std::string::npos) << report;
  EXPECT_NE(report.find("12 frames did not converge: 10 11 12 13 14 15 16 17 "
                        "18 19 ..."),
            std::string::npos)
      << report;
  EXPECT_EQ(report.find("converged\n"), std::string::npos) << report;
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
