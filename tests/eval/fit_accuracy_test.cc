// tests: the fit accuracy measurement (eval/fit_accuracy.h) on estimates
// made from the truth itself, with known camera and heading errors, and the
// bench fit options' checks (eval/fit_benchmark.h).
#include "eval/fit_accuracy.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "common/error.h"
#include "eval/fit_benchmark.h"
#include "fit/camera_model.h"
#include "motion/motion_io.h"
#include "sim/simulation.h"
#include "test_paths.h"

namespace m2d {
namespace {

using testing::SourcePath;

constexpr double kDeg = M_PI / 180.0;

std::shared_ptr<const Character> Humanoid() {
  static std::shared_ptr<const Character> character =
      LoadCharacterForSimulation(SourcePath("assets/characters/humanoid.yaml"),
                                 "flat", SimulationOptions());
  return character;
}

// The walk (in the repository) seen by one static camera.
ReferenceBundle WalkBundle(const Character& character) {
  const Motion3D motion = ReadDeepMimicMotion(
      SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt"),
      character.shared_skeleton());
  BundleFromMotionOptions options;
  options.rig.num_views = 1;
  return MakeBundleFromMotion(motion, character.keypoint_map(), options,
                              "walk");
}

// An "estimate" that is the truth: the true camera and poses.
ViewEstimate TruthAsEstimate(const ReferenceBundle& bundle,
                             const Character& character) {
  ViewEstimate estimate;
  estimate.cameras = bundle.views[0].cameras;
  estimate.skeleton_name = character.skeleton().name;
  estimate.poses = bundle.ground_truth->poses;
  estimate.residual_px.assign(estimate.poses.size(), 0.0);
  estimate.summary.num_frames = static_cast<int>(estimate.poses.size());
  estimate.summary.mean_reprojection_px = 1.5;
  estimate.summary.seconds = 2.0;
  estimate.summary.unconverged_frames = {3};
  return estimate;
}

TEST(MeasureFitAccuracy, TheTruthItselfHasNoError) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  const ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  const FitAccuracy accuracy = MeasureFitAccuracy(
      estimate, bundle.views[0].cameras, *bundle.ground_truth, *character);
  const int num_frames = bundle.num_frames();
  EXPECT_EQ(accuracy.num_frames, num_frames);
  EXPECT_NEAR(accuracy.focal_error_pct, 0.0, 1e-9);
  EXPECT_NEAR(accuracy.pitch_error_deg, 0.0, 1e-9);
  EXPECT_NEAR(accuracy.roll_error_deg, 0.0, 1e-9);
  EXPECT_NEAR(accuracy.root_relative_mpjpe_mm, 0.0, 1e-6);
  EXPECT_NEAR(accuracy.pa_mpjpe_mm, 0.0, 1e-3);
  // The walk stays inside the character's joint ranges: nothing to clamp.
  EXPECT_NEAR(accuracy.reachable_pa_mpjpe_mm, 0.0, 1e-3);
  // The rig's camera: elevation 10 deg looking at the subject, level.
  EXPECT_NEAR(accuracy.true_pitch_deg, 10.0, 1e-6);
  EXPECT_NEAR(accuracy.true_roll_deg, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(accuracy.mean_reprojection_px, 1.5);
  EXPECT_NEAR(accuracy.seconds_per_100_frames, 200.0 / num_frames, 1e-12);
  EXPECT_NEAR(accuracy.unconverged_fraction, 1.0 / num_frames, 1e-12);
}

TEST(MeasureFitAccuracy, AWrongCameraGivesItsDegreesAndPercent) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  const double centre[3] = {-4.0, 0.5, 1.7};
  const double truth_angles[2] = {12 * kDeg, -1 * kDeg};
  const double wrong_angles[2] = {17 * kDeg, 2 * kDeg};
  const std::vector<PinholeCamera> truth = {
      ToPinholeCamera(1000, truth_angles, centre, 1920, 1080)};
  estimate.cameras = {ToPinholeCamera(1100, wrong_angles, centre, 1920, 1080)};
  const FitAccuracy accuracy =
      MeasureFitAccuracy(estimate, truth, *bundle.ground_truth, *character);
  EXPECT_NEAR(accuracy.focal_error_pct, 10.0, 1e-9);
  EXPECT_NEAR(accuracy.pitch_error_deg, 5.0, 1e-9);
  EXPECT_NEAR(accuracy.roll_error_deg, 3.0, 1e-9);
  EXPECT_NEAR(accuracy.pitch_deg, 17.0, 1e-9);
  EXPECT_NEAR(accuracy.true_pitch_deg, 12.0, 1e-9);
  EXPECT_NEAR(accuracy.roll_deg, 2.0, 1e-9);
  // Focal too short is as wrong as too long.
  estimate.cameras = {ToPinholeCamera(900, truth_angles, centre, 1920, 1080)};
  EXPECT_NEAR(
      MeasureFitAccuracy(estimate, truth, *bundle.ground_truth, *character)
          .focal_error_pct,
      10.0, 1e-9);
}

TEST(MeasureFitAccuracy, AMovingCameraIsAveragedOverFrames) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  const int num_frames = bundle.num_frames();
  const double centre[3] = {-4.0, 0.0, 1.7};
  const double truth_angles[2] = {10 * kDeg, 0.0};
  const std::vector<PinholeCamera> truth = {
      ToPinholeCamera(1000, truth_angles, centre, 1920, 1080)};
  // Every other frame's pitch is 4 deg off; the centre moves (ignored).
  estimate.cameras.clear();
  int off = 0;
  for (int t = 0; t < num_frames; ++t) {
    const double angles[2] = {(t % 2 ? 14 : 10) * kDeg, 0.0};
    const double moved[3] = {-4.0 + 0.05 * t, 0.0, 1.7};
    estimate.cameras.push_back(
        ToPinholeCamera(1000, angles, moved, 1920, 1080));
    off += t % 2;
  }
  const FitAccuracy accuracy =
      MeasureFitAccuracy(estimate, truth, *bundle.ground_truth, *character);
  EXPECT_NEAR(accuracy.pitch_error_deg, 4.0 * off / num_frames, 1e-9);
  EXPECT_NEAR(accuracy.pitch_deg, 10.0, 1e-9);  // frame 0
  EXPECT_NEAR(accuracy.roll_error_deg, 0.0, 1e-9);
}

TEST(MeasureFitAccuracy, PosesInAnotherHeadingAndPlaceHaveNoPoseError) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  // The fit's world: turned 100 deg about z and shifted.
  const Eigen::Quaterniond turn(
      Eigen::AngleAxisd(100 * kDeg, Eigen::Vector3d::UnitZ()));
  for (Pose3D& pose : estimate.poses) {
    pose.root_position_m =
        turn * pose.root_position_m + Eigen::Vector3d(3, -2, 0);
    pose.local_rotations[0] = turn * pose.local_rotations[0];
  }
  const FitAccuracy accuracy = MeasureFitAccuracy(
      estimate, bundle.views[0].cameras, *bundle.ground_truth, *character);
  EXPECT_NEAR(accuracy.root_relative_mpjpe_mm, 0.0, 1e-6);
  EXPECT_NEAR(accuracy.pa_mpjpe_mm, 0.0, 1e-3);

  // A bent pose is an error.
  ViewEstimate bent = TruthAsEstimate(bundle, *character);
  for (Pose3D& pose : bent.poses) {
    for (size_t j = 1; j < pose.local_rotations.size(); ++j) {
      pose.local_rotations[j] =
          pose.local_rotations[j] *
          Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
    }
  }
  const FitAccuracy bent_accuracy = MeasureFitAccuracy(
      bent, bundle.views[0].cameras, *bundle.ground_truth, *character);
  EXPECT_GT(bent_accuracy.root_relative_mpjpe_mm, 20.0);
  EXPECT_GT(bent_accuracy.pa_mpjpe_mm, 10.0);
}

// An arm fitted in another solution (the right shoulder turned 90 deg, the
// arm raised forward where the truth's hangs) is named: its wrist is the
// worst keypoint, which the mean PA-MPJPE does not say.
TEST(MeasureFitAccuracy, AnArmFittedWrongIsNamedAsTheWorstKeypoint) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  const int shoulder = character->skeleton().IndexOf("right_shoulder");
  ASSERT_GE(shoulder, 0);
  for (Pose3D& pose : estimate.poses) {
    pose.local_rotations[shoulder] = pose.local_rotations[shoulder] *
                                     Eigen::Quaterniond(Eigen::AngleAxisd(
                                         -90 * kDeg, Eigen::Vector3d::UnitY()));
  }
  const FitAccuracy accuracy = MeasureFitAccuracy(
      estimate, bundle.views[0].cameras, *bundle.ground_truth, *character);
  ASSERT_EQ(accuracy.pa_per_keypoint_mm.size(), 17u);
  ASSERT_GE(accuracy.WorstKeypoint(), 0);
  EXPECT_EQ(accuracy.keypoint_names[accuracy.WorstKeypoint()], "right_wrist");
  EXPECT_GT(accuracy.pa_per_keypoint_mm[accuracy.WorstKeypoint()],
            3.0 * accuracy.pa_mpjpe_mm);
  EXPECT_NE(accuracy.BriefReport().find("worst keypoint right_wrist"),
            std::string::npos)
      << accuracy.BriefReport();
  // Averaged over views keypoint by keypoint.
  const FitAccuracy mean = MeanFitAccuracy({accuracy, accuracy});
  ASSERT_EQ(mean.pa_per_keypoint_mm.size(), 17u);
  EXPECT_NEAR(mean.pa_per_keypoint_mm[accuracy.WorstKeypoint()],
              accuracy.pa_per_keypoint_mm[accuracy.WorstKeypoint()], 1e-9);
}

// A truth bent past the character's joint ranges (a left hip raised 100 deg
// sideways, as the DeepMimic kick does about 60 deg past the range) cannot
// be fitted exactly: the reachable floor says how far it is.
TEST(MeasureFitAccuracy, TruthBeyondTheJointRangesHasAReachableFloor) {
  auto character = Humanoid();
  ReferenceBundle bundle = WalkBundle(*character);
  const ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  const int left_hip = character->skeleton().IndexOf("left_hip");
  ASSERT_GE(left_hip, 0);
  GroundTruth3D& truth = *bundle.ground_truth;
  for (size_t t = 0; t < truth.poses.size(); ++t) {
    Pose3D& pose = truth.poses[t];
    pose.local_rotations[left_hip] = Eigen::Quaterniond(
        Eigen::AngleAxisd(100 * kDeg, Eigen::Vector3d::UnitX()));
    truth.keypoints_m[t] = KeypointPositions(character->skeleton(),
                                             character->keypoint_map(), pose);
  }
  const FitAccuracy accuracy =
      MeasureFitAccuracy(estimate, bundle.views[0].cameras, truth, *character);
  EXPECT_GT(accuracy.reachable_pa_mpjpe_mm, 20.0);
  EXPECT_LT(accuracy.reachable_pa_mpjpe_mm, accuracy.pa_mpjpe_mm);
}

TEST(MeasureFitAccuracy, ShapesThatDisagreeAreNamedErrors) {
  auto character = Humanoid();
  const ReferenceBundle bundle = WalkBundle(*character);
  const ViewEstimate estimate = TruthAsEstimate(bundle, *character);
  ViewEstimate short_estimate = estimate;
  short_estimate.poses.pop_back();
  EXPECT_THROW(MeasureFitAccuracy(short_estimate, bundle.views[0].cameras,
                                  *bundle.ground_truth, *character),
               InputError);
  ViewEstimate no_cameras = estimate;
  no_cameras.cameras.clear();
  EXPECT_THROW(MeasureFitAccuracy(no_cameras, bundle.views[0].cameras,
                                  *bundle.ground_truth, *character),
               InputError);
  EXPECT_THROW(
      MeasureFitAccuracy(estimate, {}, *bundle.ground_truth, *character),
      InputError);
  ViewEstimate other_skeleton = estimate;
  other_skeleton.skeleton_name = "cmu";
  EXPECT_THROW(MeasureFitAccuracy(other_skeleton, bundle.views[0].cameras,
                                  *bundle.ground_truth, *character),
               InputError);
}

TEST(MeanFitAccuracy, AveragesEveryField) {
  FitAccuracy a, b;
  a.num_frames = 30;
  b.num_frames = 30;
  a.pitch_error_deg = 1.0;
  b.pitch_error_deg = 3.0;
  a.pa_mpjpe_mm = 40.0;
  b.pa_mpjpe_mm = 60.0;
  a.unconverged_fraction = 0.5;
  const FitAccuracy mean = MeanFitAccuracy({a, b});
  EXPECT_EQ(mean.num_frames, 30);
  EXPECT_DOUBLE_EQ(mean.pitch_error_deg, 2.0);
  EXPECT_DOUBLE_EQ(mean.pa_mpjpe_mm, 50.0);
  EXPECT_DOUBLE_EQ(mean.unconverged_fraction, 0.25);
  EXPECT_EQ(MeanFitAccuracy({}).pa_mpjpe_mm, 0.0);
}

TEST(FitBenchmarkOptions, AnUnknownClipIsNamed) {
  FitBenchmarkOptions options;
  options.motion_dir = SourcePath("assets/motions/deepmimic");
  EXPECT_NO_THROW(options.Validate());
  options.clips = {"walk", "moonwalk"};
  try {
    options.Validate();
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'moonwalk'"), std::string::npos) << message;
    EXPECT_NE(message.find("dance_a"), std::string::npos) << message;
  }
  options.MakeQuick();
  EXPECT_EQ(options.clips, std::vector<std::string>{"walk"});
  EXPECT_EQ(options.settings.size(), 1u);
  EXPECT_FALSE(options.noisy);
  EXPECT_EQ(options.num_views, 1);
  options.num_views = 0;
  EXPECT_THROW(options.Validate(), ConfigError);
}

TEST(FitBenchmarkOptions, LoopingClipsAreRepeatedToTheMinimumLength) {
  FitBenchmarkOptions options;
  options.motion_dir = SourcePath("assets/motions/deepmimic");
  auto character =
      LoadCharacterForSimulation(SourcePath("assets/characters/humanoid.yaml"),
                                 "flat", SimulationOptions());
  const FitCameraSetting setting = DefaultFitCameraSettings()[1];
  auto frames = [&](const std::string& clip) {
    const Motion3D motion = ReadDeepMimicMotion(options.MotionPath(clip),
                                                character->shared_skeleton());
    return MakeBenchmarkBundle(motion, *character, options, setting, false,
                               clip)
        .views[0]
        .clip.num_frames();
  };
  const int walk = frames("walk"), kick = frames("kick");
  EXPECT_LT(walk, 45);  // a 1.3-s cycle at 30 Hz
  options.min_duration_s = 3.0;
  EXPECT_EQ(frames("walk"), 91);    // looped to 3 s
  EXPECT_EQ(frames("kick"), kick);  // played once: its own length
  options.max_duration_s = 2.0;
  EXPECT_THROW(options.Validate(), ConfigError);  // longer than the cut
}

TEST(FitBenchmarkTable, HasARowPerCombinationAndTheMeans) {
  FitBenchmarkResult result;
  FitBenchmarkRow row;
  row.clip = "walk";
  row.setting = "A";
  row.num_frames = 39;
  row.views.resize(2);
  row.views[0].pa_mpjpe_mm = 50.0;
  row.views[1].pa_mpjpe_mm = 70.0;
  row.mean = MeanFitAccuracy(row.views);
  result.rows.push_back(row);
  row.noisy = true;
  row.views.resize(1);
  row.errors = {"walk A noisy view1: too few keypoints"};
  row.mean = MeanFitAccuracy(row.views);
  result.rows.push_back(row);
  result.num_fits = 4;
  result.num_failed_fits = 1;
  result.all = MeanFitAccuracy({result.rows[0].mean, result.rows[1].mean});
  const std::string table = FormatFitBenchmarkTable(result);
  EXPECT_NE(table.find("walk     A   clean   2/2     39"), std::string::npos)
      << table;
  EXPECT_NE(table.find("walk     A   noisy   1/2"), std::string::npos) << table;
  // The overall line: every returned fit of the 4 run.
  const size_t all = table.rfind("\nall ");
  ASSERT_NE(all, std::string::npos) << table;
  const std::string all_line = table.substr(all + 1);
  EXPECT_NE(all_line.find(" 3/4 "), std::string::npos) << table;
  EXPECT_EQ(all_line.find("clean"), std::string::npos) << table;
  const std::string markdown = FormatFitBenchmarkMarkdown(result);
  EXPECT_NE(markdown.find("| walk | A | clean | 2/2 | 39 |"), std::string::npos)
      << markdown;
  FitBenchmarkOptions options;
  const nlohmann::json json = FitBenchmarkToJson(result, options);
  EXPECT_EQ(json["rows"].size(), 2u);
  EXPECT_EQ(json["rows"][1]["errors"].size(), 1u);
  EXPECT_DOUBLE_EQ(json["rows"][0]["mean"]["pa_mpjpe_mm"].get<double>(), 60.0);
}

}  // namespace
}  // namespace m2d
