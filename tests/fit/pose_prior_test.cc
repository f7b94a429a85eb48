// tests: the learned pose prior — learned from real motion it prefers that
// motion's poses to arbitrary ones, its file round-trips, a marginal is the
// Gaussian marginal, its cost terms' Jacobians match finite differences, and
// bad files or too little data are named errors — and the retargeting of
// other skeletons' captures it is also learned from.
#include "fit/pose_prior.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <random>

#include "common/error.h"
#include "fit/costs.h"
#include "fit/fit_test_util.h"
#include "fit/kinematics.h"
#include "fit/pose_prior_training.h"
#include "fit/retarget.h"
#include "motion/motion_io.h"
#include "sim/simulation.h"
#include "test_paths.h"

namespace m2d {
namespace {

using testing::Humanoid;
using testing::SourcePath;

// Every pose of one of the repository's clips.
std::vector<Eigen::VectorXd> RepositoryPoses(const std::string& clip) {
  const std::string path =
      SourcePath("assets/motions/deepmimic/humanoid3d_" + clip + ".txt");
  const Motion3D motion =
      ReadDeepMimicMotion(path, Humanoid()->shared_skeleton(), 30.0);
  return HingeAnglesOfMotion(*Humanoid(), motion, 1, path);
}

// A mixture learned from every clip the repository carries (210 poses).
PoseMixture LearnFromRepositoryClips(int components) {
  std::vector<Eigen::VectorXd> poses;
  for (const char* clip : {"walk", "run", "jump", "kick", "dance_a"}) {
    const std::vector<Eigen::VectorXd> more = RepositoryPoses(clip);
    poses.insert(poses.end(), more.begin(), more.end());
  }
  PoseMixtureTrainingOptions options;
  options.num_components = components;
  return TrainPoseMixture(*Humanoid(), poses, options, "test");
}

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/" + name;
}

TEST(PosePrior, PrefersTheMotionItLearnedFromToArbitraryPoses) {
  const PoseMixture mixture = LearnFromRepositoryClips(2);
  EXPECT_EQ(mixture.num_components(), 2);
  EXPECT_EQ(mixture.num_hinges(), Humanoid()->num_actions());
  EXPECT_EQ(mixture.hinge_names.front(), "abdomen_x");
  // The walk's poses against poses drawn uniformly within the joint ranges.
  double walk_cost = 0.0;
  const std::vector<Eigen::VectorXd> walk = RepositoryPoses("walk");
  for (const Eigen::VectorXd& pose : walk)
    walk_cost += mixture.Cost(pose.data());
  walk_cost /= walk.size();
  const KinematicModel model = KinematicModel::FromCharacter(*Humanoid());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double random_cost = 0.0;
  constexpr int kRandomPoses = 50;
  for (int i = 0; i < kRandomPoses; ++i) {
    Eigen::VectorXd pose(model.num_hinges());
    for (int h = 0; h < model.num_hinges(); ++h) {
      pose[h] = model.hinge_low_rad[h] +
                unit(rng) * (model.hinge_high_rad[h] - model.hinge_low_rad[h]);
    }
    random_cost += mixture.Cost(pose.data());
  }
  random_cost /= kRandomPoses;
  EXPECT_GE(walk_cost, 0.0);
  EXPECT_LT(10.0 * walk_cost, random_cost)
      << "walk " << walk_cost << " random " << random_cost;
}

TEST(PosePrior, FileRoundTripsAndBadFilesAreNamed) {
  const PoseMixture mixture = LearnFromRepositoryClips(2);
  const std::string path = TempPath("prior.json");
  WritePoseMixtureAtomic(mixture, path);
  const PoseMixture read = ReadPoseMixture(path);
  ASSERT_EQ(read.num_components(), mixture.num_components());
  EXPECT_EQ(read.hinge_names, mixture.hinge_names);
  for (const Eigen::VectorXd& pose : RepositoryPoses("walk")) {
    EXPECT_NEAR(read.Cost(pose.data()), mixture.Cost(pose.data()), 1e-6);
  }
  // Another character's hinges.
  std::vector<std::string> names = mixture.hinge_names;
  std::swap(names[0], names[1]);
  EXPECT_THROW(CheckPoseMixtureHinges(read, names, "x"), InputError);
  CheckPoseMixtureHinges(read, mixture.hinge_names, "x");

  auto expect_named = [](const std::string& contents, const std::string& what) {
    const std::string bad = TempPath("bad_prior.json");
    std::ofstream(bad) << contents;
    try {
      ReadPoseMixture(bad);
      ADD_FAILURE() << "no error for " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  };
  expect_named("{not json", "malformed JSON");
  expect_named(R"({"format": "something else"})", "another format");
  expect_named(
      R"({"format": "mimic2d-pose-mixture", "character": "h", "hinges": ["a"],
          "components": [{"weight": 1, "mean_rad": [0, 1],
                          "covariance_rad2": [1]}]})",
      "a mean of the wrong size");
  expect_named(
      R"({"format": "mimic2d-pose-mixture", "character": "h", "hinges": ["a"],
          "components": [{"weight": 1, "mean_rad": [0],
                          "covariance_rad2": [-1]}]})",
      "a covariance that is not positive definite");
}

TEST(PosePrior, MarginalIsTheGaussianMarginal) {
  // One component: the marginal's cost is 1/2 the Mahalanobis distance
  // under the covariance's sub-block.
  Eigen::MatrixXd root(3, 3);
  root << 1.0, 0.2, 0.1, 0.0, 0.8, 0.3, 0.0, 0.0, 0.5;
  const Eigen::MatrixXd covariance = root.transpose() * root;
  const PoseMixture mixture = PoseMixture::FromCovariances(
      "c", {"a", "b", "c"}, {1.0}, {Eigen::Vector3d(0.1, -0.2, 0.3)},
      {covariance});
  const PoseMixture marginal = mixture.Marginal({0, 2});
  ASSERT_EQ(marginal.num_hinges(), 2);
  EXPECT_EQ(marginal.hinge_names, (std::vector<std::string>{"a", "c"}));
  Eigen::Matrix2d sub;
  sub << covariance(0, 0), covariance(0, 2), covariance(2, 0), covariance(2, 2);
  const Eigen::Vector2d x(0.5, -0.4);
  const Eigen::Vector2d offset = x - Eigen::Vector2d(0.1, 0.3);
  EXPECT_NEAR(marginal.Cost(x.data()), 0.5 * offset.dot(sub.inverse() * offset),
              1e-12);
}

TEST(PosePrior, TooLittleDataIsANamedError) {
  PoseMixtureTrainingOptions options;
  options.num_components = 8;
  try {
    TrainPoseMixture(*Humanoid(), RepositoryPoses("walk"), options, "the walk");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the walk"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("too few"), std::string::npos);
  }
  std::vector<Eigen::VectorXd> poses = RepositoryPoses("jump");
  poses[3][2] = std::nan("");
  options.num_components = 1;
  EXPECT_THROW(TrainPoseMixture(*Humanoid(), poses, options, "nan"),
               InputError);
}

void ExpectJacobianMatches(ceres::CostFunction* function,
                           std::vector<double*> blocks, const char* what) {
  std::unique_ptr<ceres::CostFunction> owned(function);
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-3;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(function, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results))
      << what << ": " << results.error_log;
}

TEST(PosePrior, CostTermsJacobiansMatchFiniteDifferences) {
  const PoseMixture mixture = LearnFromRepositoryClips(2);
  std::vector<Eigen::VectorXd> walk = RepositoryPoses("walk");
  Eigen::VectorXd pose = walk[10];
  pose[3] += 0.2;
  ExpectJacobianMatches(new MixturePriorCost(&mixture, 0.05), {pose.data()},
                        "mixture prior");
  // The limb search's cost with the limb's marginal.
  const KinematicModel model = KinematicModel::FromCharacter(*Humanoid());
  const std::vector<int> hinges = {3, 4, 5, 6};
  const PoseMixture marginal = mixture.Marginal(hinges);
  LimbCost limb;
  limb.model = &model;
  limb.limb_hinges = hinges;
  limb.keypoints = {9, 10};
  limb.observed_px = {{980, 430}, {1010, 470}};
  limb.weights = {0.9, 0.6};
  limb.hinges_rad.assign(pose.data(), pose.data() + pose.size());
  limb.root_m[2] = 0.9;
  limb.focal_px = 1100;
  limb.centre_m[0] = -4.0;
  limb.centre_m[2] = 1.2;
  limb.cx_px = 960;
  limb.cy_px = 540;
  limb.inv_scale_px = 1.0 / 120.0;
  limb.penetration_weight = 100.0;
  limb.limb_mixture = &marginal;
  limb.mixture_weight = 0.05;
  std::vector<double> angles{0.3, -0.4, 0.2, -0.9};
  ExpectJacobianMatches(LimbCost::Create(limb), {angles.data()},
                        "limb with the mixture");
}

}  // namespace
}  // namespace m2d

namespace m2d {
namespace {

// The character's own keypoints come back to its own angles: the knees and
// elbows (which the 17 points fix) to within a few degrees, every body
// keypoint to within a centimetre.
TEST(Retarget, RecoversTheCharactersOwnPoses) {
  const std::string path =
      SourcePath("assets/motions/deepmimic/humanoid3d_run.txt");
  const Motion3D motion =
      ReadDeepMimicMotion(path, Humanoid()->shared_skeleton(), 30.0);
  std::vector<std::vector<Eigen::Vector3d>> points;
  for (const Pose3D& pose : motion.frames) {
    points.push_back(KeypointPositions(Humanoid()->skeleton(),
                                       Humanoid()->keypoint_map(), pose));
  }
  RetargetSummary summary;
  const std::vector<Eigen::VectorXd> angles = RetargetKeypointsToHinges(
      *Humanoid(), points, RetargetOptions(), path, &summary);
  const std::vector<Eigen::VectorXd> truth =
      HingeAnglesOfMotion(*Humanoid(), motion, 1, path);
  ASSERT_EQ(angles.size(), truth.size());
  std::printf("own poses: keypoints %.1f mm off on average\n",
              1000 * summary.mean_error_m);
  EXPECT_NEAR(summary.scale, 1.0, 1e-9);
  EXPECT_LT(summary.mean_error_m, 0.005);
  const std::vector<std::string> names = HingeNames(*Humanoid());
  for (const char* joint :
       {"right_knee", "left_knee", "right_elbow", "left_elbow"}) {
    const int h = static_cast<int>(
        std::find(names.begin(), names.end(), joint) - names.begin());
    ASSERT_LT(h, static_cast<int>(names.size())) << joint;
    double worst = 0.0;
    for (size_t t = 0; t < angles.size(); ++t)
      worst = std::max(worst, std::abs(angles[t][h] - truth[t][h]));
    std::printf("%s: worst %.3f rad\n", joint, worst);
    EXPECT_LT(worst, 0.05) << joint;
  }
}

// A CMU capture (assimp-testmodels) on its own skeleton: scaled to the
// humanoid and fitted to a few centimetres.
TEST(Retarget, FitsACmuCaptureAndNamesBadFrames) {
  const std::string path = "/usr/share/assimp/models/BVH/01_01.bvh";
  const Motion3D motion = ReadBvhMotion(path, 0.056444, 10.0);
  const KeypointMap map = LoadKeypointMap(
      SourcePath("assets/skeletons/cmu_bvh.coco17.yaml"), *motion.skeleton);
  std::vector<std::vector<Eigen::Vector3d>> points;
  for (const Pose3D& pose : motion.frames)
    points.push_back(KeypointPositions(*motion.skeleton, map, pose));
  RetargetSummary summary;
  const std::vector<Eigen::VectorXd> angles = RetargetKeypointsToHinges(
      *Humanoid(), points, RetargetOptions(), path, &summary);
  EXPECT_EQ(angles.size(), points.size());
  std::printf("CMU 01_01: scale %.3f, keypoints %.1f mm off on average\n",
              summary.scale, 1000 * summary.mean_error_m);
  EXPECT_NEAR(summary.scale, 1.0, 0.2);
  EXPECT_LT(summary.mean_error_m, 0.035);
  const KinematicModel model = KinematicModel::FromCharacter(*Humanoid());
  for (const Eigen::VectorXd& frame : angles) {
    for (int h = 0; h < model.num_hinges(); ++h) {
      ASSERT_GE(frame[h], model.hinge_low_rad[h] - 1e-9);
      ASSERT_LE(frame[h], model.hinge_high_rad[h] + 1e-9);
    }
  }
  points[2][5].x() = std::nan("");
  try {
    RetargetKeypointsToHinges(*Humanoid(), points, RetargetOptions(), path);
    ADD_FAILURE() << "no error for a NaN keypoint";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 2"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace m2d
