#include "eval/metrics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "eval/evaluator.h"

namespace m2d {
namespace {

constexpr int kNumKeypoints = 17;  // COCO-17

// A deterministic, non-degenerate COCO-17 pose per frame: keypoint j sits at
// a distinct place that also moves with t.
KeypointFrames MakePoses(int num_frames) {
  KeypointFrames frames(num_frames);
  for (int t = 0; t < num_frames; ++t) {
    for (int j = 0; j < kNumKeypoints; ++j) {
      frames[t].push_back(
          {0.1 * j + 0.01 * t, 0.05 * (j % 5) - 0.02 * t, 1.7 - 0.1 * j});
    }
  }
  return frames;
}

KeypointFrames Translated(KeypointFrames frames,
                          const Eigen::Vector3d& offset_m) {
  for (auto& frame : frames) {
    for (Eigen::Vector3d& point : frame) point += offset_m;
  }
  return frames;
}

TEST(MeanPositionError, ConstantOffsetGivesItsLength) {
  const KeypointFrames truth = MakePoses(5);
  // A 3-4-5 triangle in centimetres: every keypoint is 5 cm off.
  const KeypointFrames simulated = Translated(truth, {0.03, 0.04, 0.0});
  EXPECT_NEAR(MeanPositionError(simulated, truth), 0.05, 1e-12);
  EXPECT_EQ(MeanPositionError(truth, truth), 0.0);
}

TEST(MeanPositionError, AveragesOverKeypointsAndFrames) {
  const KeypointFrames truth = MakePoses(2);
  KeypointFrames simulated = truth;
  // One keypoint of one frame off by 0.34 m: mean over 2 x 17 = 0.01 m.
  simulated[1][3].z() += 0.34;
  EXPECT_NEAR(MeanPositionError(simulated, truth), 0.01, 1e-12);
}

TEST(MeanPositionError, ComparesOnlyTheFramesBothHave) {
  const KeypointFrames truth = MakePoses(6);
  // Three simulated frames (an episode that ended early), 5 cm off.
  KeypointFrames simulated = Translated(truth, {0.0, 0.0, 0.05});
  simulated.resize(3);
  EXPECT_NEAR(MeanPositionError(simulated, truth), 0.05, 1e-12);
  EXPECT_EQ(MeanPositionError({}, truth), 0.0);
}

TEST(RootRelativePositionError, GlobalTranslationIsNotAnError) {
  const KeypointLayout& layout = Coco17Layout();
  const KeypointFrames truth = MakePoses(4);
  const KeypointFrames drifted = Translated(truth, {1.5, -2.0, 0.3});
  EXPECT_NEAR(RootRelativePositionError(drifted, truth, layout), 0.0, 1e-12);
  // The global error sees the drift.
  EXPECT_NEAR(MeanPositionError(drifted, truth),
              std::sqrt(1.5 * 1.5 + 4 + 0.09), 1e-12);
}

TEST(RootRelativePositionError, MovedWristCountsOnceAveragedOverKeypoints) {
  const KeypointLayout& layout = Coco17Layout();
  const KeypointFrames truth = MakePoses(3);
  // A drift plus a pose change: the left wrist (not a root keypoint) is
  // 0.17 m off in every frame; the root (mid-hips) is unaffected, so the
  // root-relative error is 0.17 / 17 keypoints.
  KeypointFrames simulated = Translated(truth, {0.4, 0.0, -0.2});
  const int wrist = static_cast<int>(Coco17::kLeftWrist);
  for (auto& frame : simulated) frame[wrist].y() += 0.17;
  EXPECT_NEAR(RootRelativePositionError(simulated, truth, layout), 0.01, 1e-12);
}

TEST(RootRelativePositionError, MovedHipShiftsTheRootForEveryKeypoint) {
  const KeypointLayout& layout = Coco17Layout();
  ASSERT_EQ(layout.root_keypoints,
            (std::vector<int>{static_cast<int>(Coco17::kLeftHip),
                              static_cast<int>(Coco17::kRightHip)}));
  const KeypointFrames truth = MakePoses(2);
  // Moving the left hip by d moves the root (mean of the hips) by d / 2:
  // every keypoint, the left hip included, is then d / 2 off relative to it.
  KeypointFrames simulated = truth;
  const int left_hip = static_cast<int>(Coco17::kLeftHip);
  for (auto& frame : simulated) frame[left_hip].x() += 0.2;
  EXPECT_NEAR(RootRelativePositionError(simulated, truth, layout), 0.1, 1e-12);
}

// Positions of `num_keypoints` keypoints over `num_frames` frames at `fps`,
// keypoint j following p_j(t) (in metres, t in seconds).
template <typename Trajectory>
KeypointFrames Sampled(int num_frames, int num_keypoints, double fps,
                       Trajectory trajectory) {
  KeypointFrames frames(num_frames);
  for (int t = 0; t < num_frames; ++t) {
    for (int j = 0; j < num_keypoints; ++j)
      frames[t].push_back(trajectory(j, t / fps));
  }
  return frames;
}

TEST(MeanJerk, CubicMotionHasItsExactThirdDerivative) {
  constexpr double kFps = 30.0;
  // x(t) = a t^3 (+ lower-order terms, which do not change the jerk) has
  // jerk 6a everywhere, and third finite differences of a cubic are exact.
  // a = 500 m/s^3 -> 3000 m/s^3 = 3.0 in units of 10^3 m/s^3.
  const double a = 500.0;
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 2, 2) / 3.0;  // unit
  KeypointFrames positions =
      Sampled(10, 3, kFps, [&](int j, double t) -> Eigen::Vector3d {
        return direction * (a * t * t * t + 4.0 * t * t - 0.5 * t + j);
      });
  EXPECT_NEAR(MeanJerk(positions, kFps), 3.0, 1e-6);

  // Per-keypoint jerks 6 * 100 and 6 * 300 m/s^3 average to 1.2 * 10^3.
  KeypointFrames mixed =
      Sampled(8, 2, kFps, [&](int j, double t) -> Eigen::Vector3d {
        const double coefficient = j == 0 ? 100.0 : 300.0;
        return {0.0, 0.0, coefficient * t * t * t};
      });
  EXPECT_NEAR(MeanJerk(mixed, kFps), 1.2, 1e-6);
}

TEST(MeanJerk, ScalesWithTheCubeOfTheFrameRate) {
  // The same per-frame positions read at twice the rate: 8x the jerk.
  KeypointFrames positions =
      Sampled(6, 1, 30.0, [](int, double t) -> Eigen::Vector3d {
        return {50.0 * t * t * t, 0.0, 0.0};
      });
  EXPECT_NEAR(MeanJerk(positions, 60.0), 8.0 * MeanJerk(positions, 30.0), 1e-9);
}

TEST(MeanJerk, LinearAndQuadraticMotionHaveNoJerk) {
  constexpr double kFps = 30.0;
  KeypointFrames linear =
      Sampled(12, 17, kFps, [](int j, double t) -> Eigen::Vector3d {
        return {1.3 * t + j, -0.7 * t, 0.2};
      });
  EXPECT_NEAR(MeanJerk(linear, kFps), 0.0, 1e-9);
  KeypointFrames quadratic =
      Sampled(12, 17, kFps, [](int j, double t) -> Eigen::Vector3d {
        return {-4.9 * t * t + 2.0 * t, 0.1 * j, 3.0 * t * t};
      });
  EXPECT_NEAR(MeanJerk(quadratic, kFps), 0.0, 1e-9);
}

TEST(MeanJerk, FewerThanFourFramesGiveZero) {
  // A third difference needs four frames; even a violent cubic reads 0.
  for (int frames = 0; frames < 4; ++frames) {
    KeypointFrames positions =
        Sampled(frames, 2, 30.0, [](int, double t) -> Eigen::Vector3d {
          return {1000.0 * t * t * t, 0.0, 0.0};
        });
    EXPECT_EQ(MeanJerk(positions, 30.0), 0.0) << frames << " frames";
  }
}

// `frames` mapped by x -> scale * R x + offset, one transform per frame when
// `per_frame`, else the same for all.
KeypointFrames Transformed(KeypointFrames frames,
                           const Eigen::Matrix3d& rotation, double scale,
                           const Eigen::Vector3d& offset_m,
                           bool per_frame = false) {
  for (size_t t = 0; t < frames.size(); ++t) {
    const Eigen::Matrix3d r =
        per_frame ? Eigen::Matrix3d(
                        Eigen::AngleAxisd(0.2 * t, Eigen::Vector3d::UnitX()) *
                        rotation)
                  : rotation;
    const Eigen::Vector3d shift = per_frame ? (1.0 + t) * offset_m : offset_m;
    for (Eigen::Vector3d& point : frames[t]) point = scale * r * point + shift;
  }
  return frames;
}

Eigen::Matrix3d Yaw(double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitZ())
      .toRotationMatrix();
}

TEST(YawAlignedRootRelativeError, AYawedAndShiftedCopyHasNoError) {
  const KeypointFrames truth = MakePoses(8);
  // Another world frame: turned by 2.5 rad about z and shifted.
  const KeypointFrames simulated =
      Transformed(truth, Yaw(2.5), 1.0, {3.0, -1.0, 0.0});
  double yaw_rad = 0.0;
  EXPECT_NEAR(
      YawAlignedRootRelativeError(simulated, truth, Coco17Layout(), &yaw_rad),
      0.0, 1e-12);
  EXPECT_NEAR(yaw_rad, -2.5, 1e-9);  // the turn back
  // Without the alignment, the turn is an error.
  EXPECT_GT(RootRelativePositionError(simulated, truth, Coco17Layout()), 0.1);
  // A tilt is not a yaw: it remains.
  const KeypointFrames tilted = Transformed(
      truth, Eigen::Matrix3d(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())),
      1.0, Eigen::Vector3d::Zero());
  EXPECT_GT(YawAlignedRootRelativeError(tilted, truth, Coco17Layout()), 0.05);
}

TEST(YawAlignedRootRelativeError, AnErrorAfterAlignmentIsMeasured) {
  const KeypointFrames truth = MakePoses(4);
  KeypointFrames simulated = Transformed(truth, Yaw(-1.0), 1.0, {1, 2, 0});
  // Every non-root keypoint 2 cm higher (the roots are hips 11 and 12).
  for (auto& frame : simulated) {
    for (int j = 0; j < kNumKeypoints; ++j) {
      if (j != 11 && j != 12) frame[j].z() += 0.02;
    }
  }
  // Mean over 17 keypoints of |dz - mean of the hips' dz (0)| = 15 * 2 cm.
  EXPECT_NEAR(YawAlignedRootRelativeError(simulated, truth, Coco17Layout()),
              15.0 * 0.02 / 17, 1e-9);
}

TEST(YawAlignedObjectError, FollowsTheWorldsTurnAndMeasuresTheRest) {
  const KeypointFrames truth = MakePoses(5);
  const KeypointFrames simulated =
      Transformed(truth, Yaw(2.5), 1.0, {3.0, -1.0, 0.0});
  std::vector<Eigen::Vector3d> true_ball, simulated_ball;
  for (int t = 0; t < 5; ++t) {
    true_ball.emplace_back(1.0 + 0.2 * t, 0.5, 0.11);
    simulated_ball.push_back(Yaw(2.5) * true_ball.back() +
                             Eigen::Vector3d(3.0, -1.0, 0.0));
  }
  double yaw_rad = 0.0;
  YawAlignedRootRelativeError(simulated, truth, Coco17Layout(), &yaw_rad);
  EXPECT_NEAR(YawAlignedObjectError(simulated, simulated_ball, truth, true_ball,
                                    Coco17Layout(), yaw_rad),
              0.0, 1e-9);
  // A ball 30 cm farther along every frame is 30 cm off.
  for (Eigen::Vector3d& p : simulated_ball)
    p += Yaw(2.5) * Eigen::Vector3d(0.3, 0, 0);
  EXPECT_NEAR(YawAlignedObjectError(simulated, simulated_ball, truth, true_ball,
                                    Coco17Layout(), yaw_rad),
              0.3, 1e-9);
}

TEST(ProcrustesAlignedError, ARotatedScaledShiftedCopyHasNoError) {
  const KeypointFrames truth = MakePoses(6);
  // A different similarity per frame, rotations about every axis.
  const KeypointFrames simulated =
      Transformed(truth, Yaw(0.8), 1.3, {0.5, -2.0, 0.7}, true);
  EXPECT_NEAR(ProcrustesAlignedError(simulated, truth), 0.0, 1e-9);
  EXPECT_GT(MeanPositionError(simulated, truth), 0.1);
}

TEST(ProcrustesAlignedError, APoseErrorRemains) {
  const KeypointFrames truth = MakePoses(3);
  KeypointFrames simulated = truth;
  for (auto& frame : simulated) frame[9].x() += 0.3;  // a wrist 30 cm off
  const double error = ProcrustesAlignedError(simulated, truth);
  EXPECT_GT(error, 0.005);
  // Whatever similarity moved the simulated points, the same error.
  EXPECT_NEAR(ProcrustesAlignedError(
                  Transformed(simulated, Yaw(1.0), 0.7, {1, 2, 3}), truth),
              error, 1e-9);
  EXPECT_EQ(ProcrustesAlignedError({}, truth), 0.0);
}

TEST(ProcrustesAlignedError,
     PerKeypointPointsAtTheKeypointOffAndAveragesToTheMean) {
  const KeypointFrames truth = MakePoses(4);
  KeypointFrames simulated = truth;
  for (auto& frame : simulated) frame[9].x() += 0.3;  // a wrist 30 cm off
  const std::vector<double> per_keypoint =
      ProcrustesAlignedErrorPerKeypoint(simulated, truth);
  ASSERT_EQ(per_keypoint.size(), truth[0].size());
  const auto worst = std::max_element(per_keypoint.begin(), per_keypoint.end());
  EXPECT_EQ(worst - per_keypoint.begin(), 9);
  // The alignment spreads a little of it over the others; most stays there.
  for (size_t j = 0; j < per_keypoint.size(); ++j) {
    if (j == 9) continue;
    EXPECT_LT(per_keypoint[j], 0.5 * *worst) << j;
  }
  double sum = 0.0;
  for (double error : per_keypoint) sum += error;
  EXPECT_NEAR(sum / per_keypoint.size(),
              ProcrustesAlignedError(simulated, truth), 1e-12);
  EXPECT_TRUE(ProcrustesAlignedErrorPerKeypoint({}, truth).empty());
}

EvalRow Row(const std::string& view, int episodes, double succ, double e2d_px,
            double e3d_mm) {
  EvalRow row;
  row.bundle = "walk";
  row.view = view;
  row.episodes = episodes;
  row.succ = succ;
  row.e2d_px = e2d_px;
  row.e3d_mm = e3d_mm;
  row.e3d_root_mm = e3d_mm < 0 ? -1.0 : e3d_mm / 2;
  row.e3d_pa_mm = e3d_mm < 0 ? -1.0 : e3d_mm / 4;
  row.jitter = 0.1 * episodes;
  row.mean_frames = 10.0 * episodes;
  return row;
}

TEST(AggregateRows, WeightsEachRowByItsEpisodes) {
  std::vector<EvalRow> rows = {Row("front", 2, 1.0, 10.0, 100.0),
                               Row("side", 6, 0.5, 30.0, 60.0)};
  EvalRow all = AggregateRows(rows);
  EXPECT_EQ(all.bundle, "all");
  EXPECT_EQ(all.view, "all");
  EXPECT_EQ(all.episodes, 8);
  EXPECT_DOUBLE_EQ(all.succ, (2 * 1.0 + 6 * 0.5) / 8);       // 0.625
  EXPECT_DOUBLE_EQ(all.e2d_px, (2 * 10.0 + 6 * 30.0) / 8);   // 25
  EXPECT_DOUBLE_EQ(all.e3d_mm, (2 * 100.0 + 6 * 60.0) / 8);  // 70
  EXPECT_DOUBLE_EQ(all.e3d_root_mm, 35.0);
  EXPECT_DOUBLE_EQ(all.e3d_pa_mm, (2 * 25.0 + 6 * 15.0) / 8);
  EXPECT_DOUBLE_EQ(all.jitter, (2 * 0.2 + 6 * 0.6) / 8);         // 0.5
  EXPECT_DOUBLE_EQ(all.mean_frames, (2 * 20.0 + 6 * 60.0) / 8);  // 50
  // Neither row has objects: EO2D stays "not measured".
  EXPECT_EQ(all.eo2d_px, -1.0);
}

TEST(AggregateRows, AMetricMissingFromAnyRowIsMissingFromTheAggregate) {
  // The second bundle has no 3D truth (-1): averaging the first row's E3D
  // alone would misreport it as the whole set's, so the aggregate has none.
  std::vector<EvalRow> rows = {Row("front", 4, 1.0, 12.0, 80.0),
                               Row("side", 4, 0.0, 40.0, -1.0)};
  rows[0].eo2d_px = 7.0;
  EvalRow all = AggregateRows(rows);
  EXPECT_EQ(all.e3d_mm, -1.0);
  EXPECT_EQ(all.e3d_root_mm, -1.0);
  EXPECT_EQ(all.eo2d_px, -1.0);
  // The metrics every row has are still averaged.
  EXPECT_EQ(all.episodes, 8);
  EXPECT_DOUBLE_EQ(all.succ, 0.5);
  EXPECT_DOUBLE_EQ(all.e2d_px, 26.0);
}

TEST(AggregateRows, NoEpisodesGiveAnEmptyAllRow) {
  EvalRow all = AggregateRows({});
  EXPECT_EQ(all.bundle, "all");
  EXPECT_EQ(all.episodes, 0);
  EXPECT_EQ(all.succ, 0.0);
  EXPECT_EQ(all.e3d_mm, -1.0);
}

TEST(Metrics, FrechetDistanceMatchesClosedForms) {
  // Identical Gaussians: 0. One dimension: (μa − μb)² + (σa − σb)².
  FeatureGaussian a{Eigen::VectorXd::Constant(1, 1.0),
                    Eigen::MatrixXd::Constant(1, 1, 4.0), 10};
  FeatureGaussian b{Eigen::VectorXd::Constant(1, 3.0),
                    Eigen::MatrixXd::Constant(1, 1, 9.0), 10};
  EXPECT_NEAR(FrechetDistance(a, a), 0.0, 1e-9);
  EXPECT_NEAR(FrechetDistance(a, b), 4.0 + 1.0, 1e-9);
  // Commuting (diagonal) covariances: per axis, summed.
  FeatureGaussian c{Eigen::Vector3d(0, 0, 0),
                    Eigen::Vector3d(1, 4, 9).asDiagonal(), 10};
  FeatureGaussian d{Eigen::Vector3d(1, 0, 2),
                    Eigen::Vector3d(4, 4, 1).asDiagonal(), 10};
  EXPECT_NEAR(FrechetDistance(c, d), 5.0 + 1.0 + 0.0 + 4.0, 1e-9);
  // Symmetric, and invariant to a rotation of both.
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  FeatureGaussian rc{rotation * c.mean,
                     rotation * c.covariance * rotation.transpose(), 10};
  FeatureGaussian rd{rotation * d.mean,
                     rotation * d.covariance * rotation.transpose(), 10};
  EXPECT_NEAR(FrechetDistance(d, c), FrechetDistance(c, d), 1e-9);
  EXPECT_NEAR(FrechetDistance(rc, rd), FrechetDistance(c, d), 1e-9);
}

TEST(Metrics, FeatureGaussianAndPairDistance) {
  Eigen::MatrixXd rows(4, 2);
  rows << 0, 0, 2, 0, 0, 2, 2, 2;
  const FeatureGaussian g = FitFeatureGaussian(rows);
  EXPECT_TRUE(g.mean.isApprox(Eigen::Vector2d(1, 1)));
  EXPECT_TRUE(g.covariance.isApprox(Eigen::Matrix2d::Identity()));
  // Pairs of distinct corners of a 2-square: 2 (sides) or 2√2 (diagonals).
  const double mean = MeanPairDistance(rows, 3000, 1);
  EXPECT_GT(mean, 2.0);
  EXPECT_LT(mean, 2.0 * std::sqrt(2.0));
  EXPECT_NEAR(mean, (4 * 2.0 + 2 * 2.0 * std::sqrt(2.0)) / 6, 0.05);
  EXPECT_EQ(MeanPairDistance(rows.topRows(1), 10, 1), 0.0);
}

TEST(Metrics, PrecisionAndRecallTellFaithfulFromCovering) {
  // Real: two clusters of 200 points. Generated: cluster A alone, then A
  // and B, then points far from both.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  auto cluster = [&](double x, int count) {
    Eigen::MatrixXd rows(count, 2);
    for (int i = 0; i < count; ++i) rows.row(i) << x + noise(rng), noise(rng);
    return rows;
  };
  Eigen::MatrixXd real(400, 2);
  real << cluster(0.0, 200), cluster(5.0, 200);
  const PrecisionRecall only_a =
      ManifoldPrecisionRecall(real, cluster(0.0, 300), 3);
  EXPECT_GT(only_a.precision, 0.95);
  EXPECT_NEAR(only_a.recall, 0.5, 0.05);
  Eigen::MatrixXd both(400, 2);
  both << cluster(0.0, 200), cluster(5.0, 200);
  const PrecisionRecall covering = ManifoldPrecisionRecall(real, both, 3);
  EXPECT_GT(covering.precision, 0.95);
  EXPECT_GT(covering.recall, 0.95);
  const PrecisionRecall far =
      ManifoldPrecisionRecall(real, cluster(20.0, 300), 3);
  EXPECT_EQ(far.precision, 0.0);
  EXPECT_EQ(far.recall, 0.0);
  // The k-th neighbour distance: on a line of points 1 apart, the 2nd
  // nearest other point of an end is 2 away, of an inner point 1.
  Eigen::MatrixXd line(5, 1);
  line << 0, 1, 2, 3, 4;
  const Eigen::VectorXd radii = KthNeighbourDistances(line, 2);
  EXPECT_DOUBLE_EQ(radii(0), 2.0);
  EXPECT_DOUBLE_EQ(radii(2), 1.0);
  EXPECT_TRUE(std::isinf(KthNeighbourDistances(line, 5)(0)));
}

}  // namespace
}  // namespace m2d
