#include "env/reward.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

TEST(Reprojection, SumsConfidenceWeightedDistancesOverPresentKeypoints) {
  const double projected[] = {0, 0, 10, 0, 100, 100};
  const bool in_front[] = {true, true, true};
  const Keypoint2D reference[] = {
      {3, 4, 1.0}, {10, 0, 0.5}, {0, 0, 0.0}};  // 5 px, 0 px, missing
  ReprojectionError error =
      MeasureReprojection(projected, in_front, reference, 3);
  EXPECT_EQ(error.num_present, 2);
  EXPECT_DOUBLE_EQ(error.weighted_sum_px, 5.0);
  EXPECT_DOUBLE_EQ(error.mean_px, 2.5);
  EXPECT_DOUBLE_EQ(error.max_px, 5.0);
  EXPECT_EQ(error.worst_keypoint, 0);
  EXPECT_FALSE(error.any_behind_camera);
  // The worst is the farthest present keypoint, wherever it is.
  const Keypoint2D far_second[] = {{3, 4, 1.0}, {10, 9, 0.5}, {0, 0, 0.0}};
  EXPECT_EQ(
      MeasureReprojection(projected, in_front, far_second, 3).worst_keypoint,
      1);
  const Keypoint2D none[] = {{0, 0, 0.0}, {0, 0, 0.0}, {0, 0, 0.0}};
  EXPECT_EQ(MeasureReprojection(projected, in_front, none, 3).worst_keypoint,
            -1);
}

TEST(Reprojection, NanReferenceIsMissingAndBehindCameraIsPenalized) {
  const double projected[] = {0, 0, NAN, NAN};
  const bool in_front[] = {true, false};
  const Keypoint2D reference[] = {{NAN, 1, 1.0}, {0, 0, 1.0}};
  ReprojectionError error =
      MeasureReprojection(projected, in_front, reference, 2, 500.0);
  EXPECT_EQ(error.num_present, 1);
  EXPECT_TRUE(error.any_behind_camera);
  EXPECT_DOUBLE_EQ(error.max_px, 500.0);
  EXPECT_TRUE(std::isfinite(error.weighted_sum_px));
  EXPECT_TRUE(ShouldExitEarly(error, 1000.0));
}

TEST(Reward, CombinesThePoseAndEnergyTermsWithTheirWeights) {
  ReprojectionError error;
  error.weighted_sum_px = 100.0;
  RewardWeights weights;
  weights.pose_weight = 0.8;
  weights.pose_alpha_per_px = 0.01;
  weights.energy_weight = 0.001;
  RewardTerms terms = ComputeReward(error, 50.0, nullptr, weights);
  EXPECT_NEAR(terms.pose, std::exp(-1.0), 1e-12);
  EXPECT_DOUBLE_EQ(terms.energy, -50.0);
  EXPECT_DOUBLE_EQ(terms.object, 0.0);
  EXPECT_NEAR(terms.total, 0.8 * std::exp(-1.0) - 0.05, 1e-12);
  // A perfect match with no effort earns exactly the pose weight.
  EXPECT_DOUBLE_EQ(
      ComputeReward(ReprojectionError(), 0.0, nullptr, weights).total, 0.8);
}

TEST(Reward, ObjectTermOnlyWhenTheObjectIsSeen) {
  RewardWeights weights;
  weights.object_weight = 0.5;
  ReprojectionError pose, object;
  EXPECT_DOUBLE_EQ(ComputeReward(pose, 0.0, &object, weights).object, 0.0);
  object.num_present = 1;
  object.weighted_sum_px = 10.0;
  RewardTerms terms = ComputeReward(pose, 0.0, &object, weights);
  EXPECT_NEAR(terms.object, std::exp(-weights.object_alpha_per_px * 10.0),
              1e-12);
  EXPECT_NEAR(terms.total, 1.0 + 0.5 * terms.object, 1e-12);
}

TEST(Reward, WorstKeypointTermFollowsTheKeypointTheEarlyExitCompares) {
  RewardWeights weights;
  ReprojectionError error;
  error.num_present = 17;
  error.weighted_sum_px = 17 * 10.0 + 40.0;  // one ankle 50 px off, 16 at 10
  error.max_px = 50.0;
  // Off by default: the reward is the pose term's alone.
  RewardTerms terms = ComputeReward(error, 0.0, nullptr, weights);
  EXPECT_DOUBLE_EQ(terms.worst, 0.0);
  EXPECT_DOUBLE_EQ(terms.total, terms.pose);

  weights.worst_weight = 0.5;
  weights.worst_alpha_per_px = 0.02;
  terms = ComputeReward(error, 0.0, nullptr, weights);
  EXPECT_NEAR(terms.worst, std::exp(-1.0), 1e-12);
  EXPECT_NEAR(terms.total, terms.pose + 0.5 * std::exp(-1.0), 1e-12);
  // The drifting keypoint costs more under the term than in the sum alone:
  // 10 px more on it lowers the worst term by a factor exp(-0.2).
  ReprojectionError worse = error;
  worse.weighted_sum_px += 10.0;
  worse.max_px += 10.0;
  const RewardTerms worse_terms = ComputeReward(worse, 0.0, nullptr, weights);
  EXPECT_NEAR(worse_terms.worst / terms.worst, std::exp(-0.2), 1e-12);
  EXPECT_NEAR(worse_terms.pose / terms.pose,
              std::exp(-10.0 * weights.pose_alpha_per_px), 1e-12);
  // A perfect match earns both weights.
  EXPECT_DOUBLE_EQ(
      ComputeReward(ReprojectionError(), 0.0, nullptr, weights).total, 1.5);
  weights.worst_alpha_per_px = 0.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
}

TEST(Reward, EarlyExitThreshold) {
  ReprojectionError error;
  error.max_px = 99.0;
  EXPECT_FALSE(ShouldExitEarly(error, 100.0));
  error.max_px = 101.0;
  EXPECT_TRUE(ShouldExitEarly(error, 100.0));
}

TEST(Reward, EarlyExitByTheMeanKeypoint) {
  // One keypoint 150 px off, the frame's mean 40 px: the worst-keypoint
  // rule ends the episode, the mean rule does not until the mean passes.
  ReprojectionError error;
  error.max_px = 150.0;
  error.mean_px = 40.0;
  EXPECT_TRUE(ShouldExitEarly(error, 100.0, FrameErrorMeasure::kWorst));
  EXPECT_FALSE(ShouldExitEarly(error, 100.0, FrameErrorMeasure::kMean));
  error.mean_px = 101.0;
  EXPECT_TRUE(ShouldExitEarly(error, 100.0, FrameErrorMeasure::kMean));
  // A keypoint behind the camera ends it under either rule.
  error.max_px = error.mean_px = 0.0;
  error.any_behind_camera = true;
  EXPECT_TRUE(ShouldExitEarly(error, 100.0, FrameErrorMeasure::kMean));
  EXPECT_TRUE(ShouldExitEarly(error, 100.0, FrameErrorMeasure::kWorst));
}

TEST(Reward, WeightsAreValidated) {
  RewardWeights weights;
  weights.pose_alpha_per_px = 0.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
  weights = RewardWeights();
  weights.energy_weight = -1.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
}

// K views as one: the worst keypoint of any view fails the frame; the mean
// error is the mean of the views that saw keypoints.
TEST(Reprojection, ViewsCombineWorstOfMaxAndMeanOfMeans) {
  ReprojectionError errors[3];
  errors[0].mean_px = 10;
  errors[0].weighted_sum_px = 170;
  errors[0].max_px = 30;
  errors[0].num_present = 17;
  errors[1].mean_px = 20;
  errors[1].weighted_sum_px = 340;
  errors[1].max_px = 120;
  errors[1].worst_keypoint = 9;
  errors[1].num_present = 17;
  errors[2].num_present = 0;  // no keypoints in this view this frame
  ReprojectionError combined = CombineViewErrors(errors, 3);
  EXPECT_DOUBLE_EQ(combined.mean_px, 15.0);
  EXPECT_DOUBLE_EQ(combined.weighted_sum_px, 255.0);
  EXPECT_DOUBLE_EQ(combined.max_px, 120.0);
  EXPECT_EQ(combined.worst_keypoint, 9);  // the worst keypoint's view's
  EXPECT_EQ(combined.worst_view, 1);
  EXPECT_EQ(combined.num_present, 34);
  EXPECT_TRUE(ShouldExitEarly(combined, 100.0));
  ReprojectionError single = CombineViewErrors(errors, 1);
  EXPECT_DOUBLE_EQ(single.max_px, 30.0);
  EXPECT_EQ(single.num_present, 17);
}

BodyTarget3D TwoJointBody() {
  BodyTarget3D body;
  body.root_position_m = {1, 2, 0.9};
  body.joint_rotations = {
      Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX())),
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()))};
  body.joint_angular_velocities_rad_s = {{1.0, 0, 0}, {0, 0.5, 0}};
  body.keypoints_m = {{1, 2, 1.6}, {1.2, 2, 0.1}};
  return body;
}

TEST(Tracking3D, AStateOnItsReferenceEarnsEveryWeight) {
  const BodyTarget3D body = TwoJointBody();
  Tracking3DError error = MeasureTracking3D(body, body);
  EXPECT_DOUBLE_EQ(error.max_keypoint_m, 0.0);
  Body3DRewardWeights weights;
  RewardTerms terms = ComputeReward3D(error, 0.0, weights, 1e-4);
  EXPECT_NEAR(terms.total, 0.5 + 0.1 + 0.15 + 0.1 + 0.15, 1e-12);
}

TEST(Tracking3D, EachErrorLowersItsTermAsDeepMimicsExponentials) {
  const BodyTarget3D reference = TwoJointBody();
  Body3DRewardWeights weights;
  // Both joints turned 0.3 rad further, about any axis: the pose term is
  // 0.5 exp(-2 * 0.18).
  BodyTarget3D bent = reference;
  bent.joint_rotations[0] =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 0.6, 0.8)) *
      bent.joint_rotations[0];
  bent.joint_rotations[1] = bent.joint_rotations[1] *
                            Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ());
  Tracking3DError error = MeasureTracking3D(bent, reference);
  EXPECT_NEAR(error.joint_rotation_sq_rad2, 0.18, 1e-12);
  EXPECT_NEAR(ComputeReward3D(error, 0.0, weights, 0.0).total,
              0.5 * std::exp(-0.36) + 0.5, 1e-12);
  // One joint spinning 2 rad/s faster: the velocity term is
  // 0.1 exp(-0.1 * 4).
  BodyTarget3D spun = reference;
  spun.joint_angular_velocities_rad_s[1].z() += 2.0;
  error = MeasureTracking3D(spun, reference);
  EXPECT_NEAR(error.joint_velocity_sq, 4.0, 1e-12);
  EXPECT_NEAR(ComputeReward3D(error, 0.0, weights, 0.0).total,
              0.9 + 0.1 * std::exp(-0.4), 1e-12);
  // The whole body 0.2 m to the side: the root term drops, the
  // root-relative keypoint term does not, the worst keypoint is 0.2 m off.
  BodyTarget3D moved = reference;
  moved.root_position_m.x() += 0.2;
  for (Eigen::Vector3d& k : moved.keypoints_m) k.x() += 0.2;
  error = MeasureTracking3D(moved, reference);
  EXPECT_NEAR(error.keypoint_local_sq_m2, 0.0, 1e-12);
  EXPECT_NEAR(error.max_keypoint_m, 0.2, 1e-12);
  EXPECT_NEAR(error.mean_keypoint_m, 0.2, 1e-12);
  EXPECT_NEAR(ComputeReward3D(error, 0.0, weights, 0.0).total,
              0.85 + 0.15 * std::exp(-5.0 * 0.04), 1e-12);
  // A turned root: 0.5 rad about z costs 0.1 * 0.25 inside the root term.
  BodyTarget3D turned = reference;
  turned.root_orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  error = MeasureTracking3D(turned, reference);
  EXPECT_NEAR(error.root_rotation_sq_rad2, 0.25, 1e-12);
  // Energy: the same penalty as the 2D reward's.
  EXPECT_NEAR(ComputeReward3D(MeasureTracking3D(reference, reference), 200.0,
                              weights, 1e-4)
                  .total,
              1.0 - 0.02, 1e-12);
}

// The two-stage baseline's ball: a world-position term, weighted as
// configured, and nothing (whatever the weight) when no object is compared.
TEST(Tracking3D, TheObjectTermRewardsTheBallsWorldPosition) {
  BodyTarget3D reference = TwoJointBody();
  Body3DRewardWeights weights;
  weights.object_weight = 0.5;
  // No objects: the body's terms alone, the weight notwithstanding.
  Tracking3DError error = MeasureTracking3D(reference, reference);
  EXPECT_EQ(error.num_objects, 0);
  EXPECT_NEAR(ComputeReward3D(error, 0.0, weights, 0.0).total, 1.0, 1e-12);
  // A ball 0.3 m off (and the body on its reference): 0.5 exp(-5 * 0.09).
  reference.object_positions_m = {{2.0, 1.0, 0.11}};
  BodyTarget3D behind = reference;
  behind.object_positions_m[0] += Eigen::Vector3d(-0.3, 0.0, 0.0);
  error = MeasureTracking3D(behind, reference);
  EXPECT_EQ(error.num_objects, 1);
  EXPECT_NEAR(error.object_sq_m2, 0.09, 1e-12);
  EXPECT_DOUBLE_EQ(error.max_keypoint_m, 0.0);  // the exit watches the body
  RewardTerms terms = ComputeReward3D(error, 0.0, weights, 0.0);
  EXPECT_NEAR(terms.object, std::exp(-0.45), 1e-12);
  EXPECT_NEAR(terms.total, 1.0 + 0.5 * std::exp(-0.45), 1e-12);
  // On its reference: the whole weight.
  EXPECT_NEAR(ComputeReward3D(MeasureTracking3D(reference, reference), 0.0,
                              weights, 0.0)
                  .total,
              1.5, 1e-12);
  weights.object_scale = -1.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
}

TEST(Tracking3D, BadWeightsAreRejected) {
  Body3DRewardWeights weights;
  weights.pose_scale = -1;
  EXPECT_THROW(weights.Validate(), ConfigError);
}

}  // namespace
}  // namespace m2d
