#include "gen/motion_dataset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common/error.h"
#include "gen/gen_test_data.h"
#include "motion/bundle.h"

namespace m2d {
namespace {

GenMotionSource WalkSource() { return testing::DeepMimicSource("walk"); }

TEST(GenDataset, FeaturesReadBackToTheSameClip) {
  // One follow-camera view of the walk, 3 s (the cycle looped).
  BundleFromMotionOptions options;
  options.rig.num_views = 1;
  options.duration_s = 3.0;
  options.follow = CameraFollow::kRootDolly;
  const GenMotionSource walk = WalkSource();
  const Clip2D clip =
      MakeBundleFromMotion(walk.motion, walk.keypoint_map, options, "walk")
          .views[0]
          .clip;
  const CanonicalClip canonical = ToCanonical(clip);
  const std::vector<float> rows = CanonicalFeatures(canonical);
  ASSERT_EQ(rows.size(), static_cast<size_t>(clip.num_frames()) *
                             CanonicalFrameSize(*clip.layout));
  const Clip2D back = FromCanonical(CanonicalFromFeatures(
      rows.data(), clip.num_frames(), *clip.layout, clip.fps,
      canonical.first_root_px, canonical.first_scale_px));
  ASSERT_EQ(back.num_frames(), clip.num_frames());
  double worst_px = 0.0;
  for (int t = 0; t < clip.num_frames(); ++t) {
    for (int j = 0; j < clip.keypoints.num_keypoints(); ++j) {
      worst_px = std::max(worst_px, (back.keypoints.at(t, j).Pixel() -
                                     clip.keypoints.at(t, j).Pixel())
                                        .norm());
    }
  }
  // float32 rows; the root is a running sum over 91 frames.
  EXPECT_LT(worst_px, 0.01);
}

TEST(GenDataset, MissingKeypointsHoldTheirLastValue) {
  CanonicalClip canonical;
  canonical.local_pose = KeypointTrack(3, 17);
  canonical.delta_root.assign(3, Eigen::Vector2d::Zero());
  canonical.delta_log_scale.assign(3, 0.0);
  for (int t = 0; t < 3; ++t)
    for (int j = 0; j < 17; ++j)
      canonical.local_pose.at(t, j) = {0.1 * t, static_cast<double>(j), 1};
  canonical.local_pose.at(0, 5).confidence = 0;  // before its first: first
  canonical.local_pose.at(2, 7).confidence = 0;  // later: the last present
  const std::vector<float> rows = CanonicalFeatures(canonical);
  const int size = CanonicalFrameSize(Coco17Layout());
  EXPECT_FLOAT_EQ(rows[0 * size + 2 * 5], 0.1f);
  EXPECT_FLOAT_EQ(rows[2 * size + 2 * 7], 0.1f);
  EXPECT_FLOAT_EQ(rows[2 * size + 2 * 8], 0.2f);
}

TEST(GenDataset, EveryMotionIsSeenFromEveryView) {
  GenViewOptions views;
  views.num_azimuths = 3;
  views.elevations_deg = {0, 25};
  const GenDataset dataset = BuildGenDataset({WalkSource()}, views, 30.0, 4.0);
  ASSERT_EQ(dataset.sequences.size(), 6u);
  EXPECT_EQ(dataset.frame_size, 37);
  // The cycle (1.2 s) looped to 4 s.
  EXPECT_EQ(dataset.sequences[0].num_frames, 121);
  EXPECT_EQ(dataset.num_frames(), 6 * 121);
  // Local poses are in units of the body's scale: unit RMS about the root.
  ASSERT_EQ(dataset.mean.size(), 37u);
  for (float s : dataset.std) EXPECT_GE(s, kMinFeatureStd);
  // Views differ: the same frame's local pose from two azimuths.
  const float* a = dataset.sequences[0].features.data();
  const float* b = dataset.sequences[1].features.data();
  double difference = 0;
  for (int c = 0; c < 34; ++c) difference += std::abs(a[c] - b[c]);
  EXPECT_GT(difference, 0.5);
  // Each sequence knows its view: elevation-major, the rig's azimuth order.
  for (int v = 0; v < 6; ++v) {
    EXPECT_EQ(dataset.sequences[v].view, v);
    const std::string suffix = "/view" + std::to_string(v % 3) + "_el" +
                               (v < 3 ? std::string("0") : std::string("25"));
    const std::string& name = dataset.sequences[v].name;
    EXPECT_EQ(name.substr(name.size() - suffix.size()), suffix);
  }
  // Cut or drawn, a sequence keeps its view.
  EXPECT_EQ(CutSequenceInTime(dataset.sequences[4], 37, 3)[2].view, 4);
  EXPECT_EQ(DrawRealStretches({dataset.sequences[5]}, 37, 30, 1, 1, 1)[0].view,
            5);
}

TEST(GenDataset, AskedForACameraTheNearestViewAnswers) {
  GenViewOptions views;
  views.num_azimuths = 3;  // 30, 150, 270 deg (the rig's first azimuth: 30)
  views.elevations_deg = {0, 25};
  EXPECT_DOUBLE_EQ(views.azimuth_deg(4), 150.0);
  EXPECT_DOUBLE_EQ(views.elevation_deg(4), 25.0);
  EXPECT_DOUBLE_EQ(views.azimuth_deg(2), 270.0);
  EXPECT_EQ(views.NearestView(30, 0), 0);
  EXPECT_EQ(views.NearestView(150, 20), 4);
  EXPECT_EQ(views.NearestView(280, 30), 5);
  EXPECT_EQ(views.NearestView(-90, 5), 2);    // 270 deg
  EXPECT_EQ(views.NearestView(100, 12), 4);   // nearer 150/25 than 30/0
  EXPECT_EQ(views.NearestView(389, -10), 0);  // 29 deg
}

TEST(GenDataset, PlacementDriftAddsUpTheSteps) {
  // Three frames of a 5-number row (one keypoint, root step, log-scale
  // step): the first row's steps come from before the sequence and do not
  // count; the scale doubles at frame 1, so frame 1's and frame 2's root
  // steps count twice in first-frame units.
  GenSequence sequence;
  sequence.num_frames = 3;
  sequence.features = {0, 0, 9.0f, 9.0f, 1.0f,  // ignored
                       0, 0, 0.5f, 0.0f, static_cast<float>(std::log(2.0)),
                       0, 0, 0.0f, 1.0f, 0.0f};
  const PlacementDrift drift = PlacementDriftOf(sequence, 5);
  EXPECT_NEAR(drift.log_scale_change, std::log(2.0), 1e-6);
  EXPECT_NEAR(drift.root_displacement.x(), 1.0, 1e-6);
  EXPECT_NEAR(drift.root_displacement.y(), 2.0, 1e-6);
  // The data's cameras follow the walker: a walk looped to 20 s seen from
  // a view ends near where it began.
  GenViewOptions views;
  views.num_azimuths = 2;
  views.elevations_deg = {10};
  const GenDataset dataset = BuildGenDataset({WalkSource()}, views, 30.0, 20.0);
  for (const GenSequence& real : dataset.sequences) {
    const PlacementDrift real_drift = PlacementDriftOf(real, 37);
    EXPECT_LT(std::abs(real_drift.log_scale_change), 0.15) << real.name;
    EXPECT_LT(real_drift.root_displacement.norm(), 0.5) << real.name;
  }
}

TEST(GenDataset, LargestPoseStepsAreEachFramesFastestKeypoint) {
  // Two keypoints (x, y each), then the root and log-scale steps, which are
  // not pose: frame 1 moves keypoint 1 by (3, 4), frame 2 keypoint 0 by
  // (0, 1) and the root a long way.
  GenSequence sequence;
  sequence.num_frames = 3;
  sequence.features = {0, 0, 0, 0, 0, 0, 0,  //
                       0, 0, 3, 4, 0, 0, 0,  //
                       0, 1, 3, 4, 9, 9, 1};
  const std::vector<double> steps = LargestPoseSteps(sequence, 7);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_DOUBLE_EQ(steps[0], 5.0);
  EXPECT_DOUBLE_EQ(steps[1], 1.0);
  // Real walking seen from a view: no frame steps a keypoint by a body
  // scale (the 99.9th percentile the eval's jumps are counted against).
  GenViewOptions views;
  views.num_azimuths = 1;
  views.elevations_deg = {10};
  const GenDataset dataset = BuildGenDataset({WalkSource()}, views, 30.0, 4.0);
  for (double step : LargestPoseSteps(dataset.sequences[0], 37))
    EXPECT_LT(step, 0.5);
}

TEST(GenDataset, AnAnchoredPlacementReturnsToItsStart) {
  // A stream whose steps all push one way (log scale +0.001, root +0.01
  // body scales per frame): unanchored it drifts without bound; anchored
  // with a 2-s return at 30 Hz it settles where the push and the return
  // balance (step = return_per_frame * accumulated: 0.001 * 60 = 0.06).
  const int frames = 1800, size = 5;
  std::vector<float> rows;
  for (int t = 0; t < frames; ++t)
    rows.insert(rows.end(), {0.f, 0.f, 0.01f, 0.f, 0.001f});
  GenSequence free{"free", frames, rows}, anchored{"anchored", frames, rows};
  PlacementAnchor anchor(2.0, 30.0);
  // In two calls: the anchor carries its state across them.
  anchor.Apply(anchored.features.data(), 700, size);
  anchor.Apply(anchored.features.data() + 700 * size, frames - 700, size);
  EXPECT_NEAR(PlacementDriftOf(free, size).log_scale_change, 1.799, 1e-3);
  const PlacementDrift drift = PlacementDriftOf(anchored, size);
  EXPECT_NEAR(drift.log_scale_change, 0.06, 0.003);
  // The root: 0.01 body scales of this frame's scale (e^0.06 of the first)
  // against 1/60 of the displacement.
  EXPECT_NEAR(drift.root_displacement.x(), 0.01 * std::exp(0.06) * 60, 0.02);
  EXPECT_NEAR(drift.root_displacement.y(), 0.0, 1e-6);
  // Off: rows as they are.
  GenSequence untouched = free;
  PlacementAnchor(0.0, 30.0).Apply(untouched.features.data(), frames, size);
  EXPECT_EQ(untouched.features, free.features);
  EXPECT_THROW(PlacementAnchor(-1.0, 30.0), ConfigError);
}

// The farthest the image root wanders from its first frame, horizontally,
// in body scales (the sum of the root's x steps).
double FarthestRootWanderX(const GenSequence& sequence, int frame_size) {
  double x = 0.0, farthest = 0.0;
  for (int t = 1; t < sequence.num_frames; ++t) {
    x += sequence.features[static_cast<size_t>(t) * frame_size +
                           RootStepColumn(frame_size)];
    farthest = std::max(farthest, std::abs(x));
  }
  return farthest;
}

// With follow_smoothing_s 0 the dolly follows the walker's root itself, so
// its image root only sways with the hips' keypoints about the root;
// averaged over 1 s, the path runs straight through the walker's sway and
// the image root sways with it. (Until 2026-11-27 the averaging window was
// cut on one side at the ends, the path lagged there and the root crossed
// the image: 0.93 body scales.)
TEST(GenDataset, ADollyOnTheRootKeepsTheImageRootInPlace) {
  GenViewOptions views;
  views.num_azimuths = 4;
  views.elevations_deg = {10};
  const GenDataset smoothed = BuildGenDataset({WalkSource()}, views, 30.0, 4.0);
  views.follow_smoothing_s = 0.0;
  const GenDataset pinned = BuildGenDataset({WalkSource()}, views, 30.0, 4.0);
  ASSERT_EQ(pinned.sequences.size(), smoothed.sequences.size());
  double worst_pinned = 0.0, worst_smoothed = 0.0;
  for (size_t i = 0; i < pinned.sequences.size(); ++i) {
    worst_pinned =
        std::max(worst_pinned,
                 FarthestRootWanderX(pinned.sequences[i], pinned.frame_size));
    worst_smoothed = std::max(
        worst_smoothed,
        FarthestRootWanderX(smoothed.sequences[i], smoothed.frame_size));
  }
  std::printf(
      "farthest image-root wander (body scales): pinned %.3f, "
      "smoothed %.3f\n",
      worst_pinned, worst_smoothed);
  EXPECT_LT(worst_pinned, 0.01);    // measured 0.001
  EXPECT_GT(worst_smoothed, 0.03);  // measured 0.054
  views.follow_smoothing_s = -1.0;
  EXPECT_THROW(views.Validate(), ConfigError);
}

// The walker's facing in the image: the left shoulder's local x minus the
// right's (body scales), averaged over `frames` from `first`.
double MeanShoulderWidth(const GenSequence& sequence, int frame_size, int first,
                         int frames) {
  const int left = Coco17Layout().IndexOf("left_shoulder");
  const int right = Coco17Layout().IndexOf("right_shoulder");
  double sum = 0.0;
  for (int t = first; t < first + frames; ++t) {
    const float* row =
        sequence.features.data() + static_cast<size_t>(t) * frame_size;
    sum += row[2 * left] - row[2 * right];
  }
  return sum / frames;
}

// Under a following camera at a fixed azimuth, the wrapped walk turns in
// the image over 20 s (it goes round a wide circle); straightened, it is
// seen from the same side throughout.
TEST(GenDataset, AStraightLoopKeepsItsFacing) {
  GenViewOptions views;
  views.num_azimuths = 4;
  views.elevations_deg = {10};
  views.follow_smoothing_s = 0.0;
  const GenDataset wrapped = BuildGenDataset({WalkSource()}, views, 30.0, 20.0);
  const GenDataset straight = BuildGenDataset({WalkSource()}, views, 30.0, 20.0,
                                              LoopHeading::kStraight);
  double turned_least = 1e9, straight_most = 0.0;
  for (size_t i = 0; i < wrapped.sequences.size(); ++i) {
    const int size = wrapped.frame_size;
    const int last = wrapped.sequences[i].num_frames - 60;
    turned_least = std::min(
        turned_least,
        std::abs(MeanShoulderWidth(wrapped.sequences[i], size, last, 60) -
                 MeanShoulderWidth(wrapped.sequences[i], size, 0, 60)));
    straight_most = std::max(
        straight_most,
        std::abs(MeanShoulderWidth(straight.sequences[i], size, last, 60) -
                 MeanShoulderWidth(straight.sequences[i], size, 0, 60)));
  }
  EXPECT_GT(turned_least, 0.2);
  EXPECT_LT(straight_most, 0.05);
}

TEST(GenDataset, RejectsViewsThatCannotBe) {
  GenViewOptions views;
  views.elevations_deg = {};
  EXPECT_THROW(views.Validate(), ConfigError);
  views.elevations_deg = {85};
  EXPECT_THROW(views.Validate(), ConfigError);
  views.elevations_deg = {10};
  views.num_azimuths = 0;
  EXPECT_THROW(views.Validate(), ConfigError);
}

TEST(GenDataset, ASequenceSplitInTimeKeepsEveryRowOnce) {
  const int frame_size = 3;
  GenSequence sequence{"walk/0", 5, {}};
  for (int i = 0; i < 5 * frame_size; ++i)
    sequence.features.push_back(static_cast<float>(i));
  const auto [first, second] = SplitSequenceInTime(sequence, frame_size);
  EXPECT_EQ(first.name, "walk/0/first");
  EXPECT_EQ(second.name, "walk/0/second");
  ASSERT_EQ(first.num_frames, 2);
  ASSERT_EQ(second.num_frames, 3);
  ASSERT_EQ(first.features.size(), 2u * frame_size);
  ASSERT_EQ(second.features.size(), 3u * frame_size);
  EXPECT_EQ(first.features.front(), 0.0f);
  EXPECT_EQ(second.features.front(), 6.0f);  // row 2
  EXPECT_EQ(second.features.back(), 14.0f);
}

TEST(GenDataset, ASequenceCutInTimeKeepsEveryRowOnceInOrder) {
  const int frame_size = 2;
  GenSequence sequence{"walk/0", 10, {}};
  for (int i = 0; i < 10 * frame_size; ++i)
    sequence.features.push_back(static_cast<float>(i));
  const std::vector<GenSequence> parts =
      CutSequenceInTime(sequence, frame_size, 3);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].name, "walk/0/1");
  EXPECT_EQ(parts[2].name, "walk/0/3");
  EXPECT_EQ(parts[0].num_frames, 3);  // the shorter parts first
  EXPECT_EQ(parts[1].num_frames, 3);
  EXPECT_EQ(parts[2].num_frames, 4);
  std::vector<float> joined;
  for (const GenSequence& part : parts) {
    ASSERT_EQ(part.features.size(),
              static_cast<size_t>(part.num_frames) * frame_size);
    joined.insert(joined.end(), part.features.begin(), part.features.end());
  }
  EXPECT_EQ(joined, sequence.features);
  EXPECT_THROW(CutSequenceInTime(sequence, frame_size, 11), ConfigError);
  EXPECT_THROW(CutSequenceInTime(sequence, frame_size, 0), ConfigError);
}

TEST(GenDataset, RealStretchesAreDrawnAsTheGenerationsWillBe) {
  // Two sequences whose rows count frames (row t of sequence k holds
  // 100 k + t): every stretch is a run of consecutive rows of one of them.
  const int frame_size = 2;
  std::vector<GenSequence> sequences(2);
  for (int k = 0; k < 2; ++k) {
    sequences[k].name = "walk/" + std::to_string(k);
    sequences[k].num_frames = k == 0 ? 30 : 8;  // the second is short
    for (int t = 0; t < sequences[k].num_frames; ++t)
      for (int c = 0; c < frame_size; ++c)
        sequences[k].features.push_back(static_cast<float>(100 * k + t));
  }
  const std::vector<GenSequence> stretches =
      DrawRealStretches(sequences, frame_size, 10, 12, 1, 7);
  ASSERT_EQ(stretches.size(), 12u);
  bool saw[2] = {false, false};
  for (const GenSequence& stretch : stretches) {
    ASSERT_EQ(stretch.features.size(),
              static_cast<size_t>(stretch.num_frames) * frame_size);
    const int k = static_cast<int>(stretch.features[0]) / 100;
    saw[k] = true;
    // A whole stretch where the sequence holds one, all of a short one.
    EXPECT_EQ(stretch.num_frames, k == 0 ? 10 : 8) << stretch.name;
    for (int t = 1; t < stretch.num_frames; ++t)
      EXPECT_EQ(stretch.features[t * frame_size], stretch.features[0] + t);
  }
  EXPECT_TRUE(saw[0] && saw[1]);
  // The same seed, the same draws.
  const std::vector<GenSequence> again =
      DrawRealStretches(sequences, frame_size, 10, 12, 1, 7);
  ASSERT_EQ(again.size(), stretches.size());
  for (size_t i = 0; i < again.size(); ++i)
    EXPECT_EQ(again[i].name, stretches[i].name);
  // Sequences shorter than min_frames are never drawn.
  for (const GenSequence& stretch :
       DrawRealStretches(sequences, frame_size, 10, 12, 9, 7))
    EXPECT_LT(stretch.features[0], 100.0f) << stretch.name;
  EXPECT_THROW(DrawRealStretches({}, frame_size, 10, 95, 1, 7), ConfigError);
  EXPECT_THROW(DrawRealStretches(sequences, frame_size, 0, 95, 1, 7),
               ConfigError);
  EXPECT_THROW(DrawRealStretches(sequences, frame_size, 10, 0, 1, 7),
               ConfigError);
  EXPECT_THROW(DrawRealStretches(sequences, frame_size, 10, 12, 31, 7),
               ConfigError);
}

}  // namespace
}  // namespace m2d
