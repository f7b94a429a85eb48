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
  EXPECT_FALSE(error.any_behind_camera);
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

TEST(Reward, EarlyExitThreshold) {
  ReprojectionError error;
  error.max_px = 99.0;
  EXPECT_FALSE(ShouldExitEarly(error, 100.0));
  error.max_px = 101.0;
  EXPECT_TRUE(ShouldExitEarly(error, 100.0));
}

TEST(Reward, WeightsAreValidated) {
  RewardWeights weights;
  weights.pose_alpha_per_px = 0.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
  weights = RewardWeights();
  weights.energy_weight = -1.0;
  EXPECT_THROW(weights.Validate(), ConfigError);
}

}  // namespace
}  // namespace m2d
