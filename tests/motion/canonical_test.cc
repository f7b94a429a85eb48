#include "motion/canonical.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/error.h"

namespace m2d {
namespace {

constexpr int kJ = 17;
constexpr int kLeftHip = static_cast<int>(Coco17::kLeftHip);
constexpr int kRightHip = static_cast<int>(Coco17::kRightHip);

Keypoint2D Missing() { return {NAN, NAN, 0.0}; }

// A random walking-around clip: a fixed body shape that wobbles, carried by
// a drifting root and a drifting scale, with random missing keypoints,
// frames with both hips missing and a few fully missing frames.
Clip2D RandomClip(unsigned seed, int num_frames) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> probability(0.0, 1.0);
  std::vector<Eigen::Vector2d> body(kJ);
  for (Eigen::Vector2d& point : body) point = {unit(random), unit(random)};

  Clip2D clip;
  clip.keypoints = KeypointTrack(num_frames, kJ);
  Eigen::Vector2d root(960.0, 540.0);
  double scale = 150.0;
  for (int t = 0; t < num_frames; ++t) {
    root += Eigen::Vector2d(4.0 * unit(random), 2.0 * unit(random));
    scale *= std::exp(0.02 * unit(random));
    const double frame_kind = probability(random);
    for (int j = 0; j < kJ; ++j) {
      Eigen::Vector2d local =
          body[j] + 0.1 * Eigen::Vector2d(unit(random), unit(random));
      Eigen::Vector2d pixel = root + scale * local;
      bool missing = probability(random) < 0.2 ||
                     frame_kind < 0.03 ||  // nothing detected
                     (frame_kind < 0.08 && (j == kLeftHip || j == kRightHip));
      clip.keypoints.at(t, j) =
          missing ? Missing()
                  : Keypoint2D{pixel.x(), pixel.y(),
                               0.05 + 0.95 * probability(random)};
    }
  }
  return clip;
}

TEST(RootAndScale, MeanOfHipsAndRmsDistance) {
  std::vector<Keypoint2D> frame(kJ, Missing());
  frame[kLeftHip] = {10.0, 20.0, 0.9};
  frame[kRightHip] = {14.0, 20.0, 0.8};
  frame[0] = {12.0, 26.0, 0.7};  // nose 6 px above the root
  Eigen::Vector2d root;
  double scale = 0.0;
  ASSERT_TRUE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale));
  EXPECT_DOUBLE_EQ(root.x(), 12.0);
  EXPECT_DOUBLE_EQ(root.y(), 20.0);
  EXPECT_DOUBLE_EQ(scale, std::sqrt((4.0 + 4.0 + 36.0) / 3.0));

  // One hip is enough for the root.
  frame[kLeftHip] = Missing();
  ASSERT_TRUE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale));
  EXPECT_DOUBLE_EQ(root.x(), 14.0);
  EXPECT_DOUBLE_EQ(scale, std::sqrt((0.0 + 4.0 + 36.0) / 2.0));
}

TEST(RootAndScale, RefusesFramesWithoutRootOrSpread) {
  std::vector<Keypoint2D> frame(kJ, Missing());
  Eigen::Vector2d root(-1.0, -1.0);
  double scale = -1.0;
  frame[0] = {1.0, 2.0, 1.0};
  frame[1] = {3.0, 2.0, 1.0};
  EXPECT_FALSE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale))
      << "no hip present";
  frame[0] = frame[1] = Missing();
  frame[kLeftHip] = {5.0, 5.0, 1.0};
  EXPECT_FALSE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale))
      << "a single keypoint";
  frame[kRightHip] = {5.0, 5.0, 1.0};
  EXPECT_FALSE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale))
      << "zero spread";
  frame[kRightHip] = {5.0, NAN, 1.0};  // NaN counts as missing
  EXPECT_FALSE(RootAndScale(frame.data(), Coco17Layout(), &root, &scale));
  EXPECT_EQ(root, Eigen::Vector2d(-1.0, -1.0)) << "outputs untouched";
  EXPECT_EQ(scale, -1.0);
}

TEST(Canonical, InverseRecoversRandomClips) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Clip2D clip = RandomClip(seed, 600);
    CanonicalClip canonical = ToCanonical(clip);
    ASSERT_EQ(canonical.num_frames(), 600);
    ASSERT_EQ(canonical.delta_root.size(), 600u);
    ASSERT_EQ(canonical.delta_log_scale.size(), 600u);
    Clip2D back = FromCanonical(canonical);
    ASSERT_EQ(back.num_frames(), clip.num_frames());
    EXPECT_EQ(back.layout, clip.layout);
    EXPECT_EQ(back.fps, clip.fps);
    int present = 0;
    double worst_px = 0.0;
    for (int t = 0; t < clip.num_frames(); ++t) {
      for (int j = 0; j < kJ; ++j) {
        const Keypoint2D& original = clip.keypoints.at(t, j);
        const Keypoint2D& local = canonical.local_pose.at(t, j);
        const Keypoint2D& restored = back.keypoints.at(t, j);
        ASSERT_EQ(local.IsPresent(), original.IsPresent());
        ASSERT_EQ(restored.IsPresent(), original.IsPresent());
        EXPECT_EQ(restored.confidence, original.confidence);
        if (!original.IsPresent()) continue;
        ++present;
        worst_px =
            std::max(worst_px, (restored.Pixel() - original.Pixel()).norm());
      }
    }
    EXPECT_LT(worst_px, 1e-9);
    EXPECT_GT(present, 600 * kJ / 2);  // the clip really has content
  }
}

TEST(Canonical, LocalPoseIgnoresTranslationAndScale) {
  Clip2D clip = RandomClip(7, 300);
  Clip2D moved = clip;
  const Eigen::Vector2d shift(-345.25, 812.5);
  const double zoom = 2.75;
  for (int t = 0; t < clip.num_frames(); ++t) {
    for (int j = 0; j < kJ; ++j) {
      Keypoint2D& point = moved.keypoints.at(t, j);
      point.x_px = zoom * point.x_px + shift.x();
      point.y_px = zoom * point.y_px + shift.y();
    }
  }
  CanonicalClip a = ToCanonical(clip);
  CanonicalClip b = ToCanonical(moved);
  for (int t = 0; t < clip.num_frames(); ++t) {
    for (int j = 0; j < kJ; ++j) {
      const Keypoint2D& pa = a.local_pose.at(t, j);
      const Keypoint2D& pb = b.local_pose.at(t, j);
      ASSERT_EQ(pa.IsPresent(), pb.IsPresent());
      if (!pa.IsPresent()) continue;
      EXPECT_NEAR(pa.x_px, pb.x_px, 1e-12);
      EXPECT_NEAR(pa.y_px, pb.y_px, 1e-12);
    }
    EXPECT_NEAR((a.delta_root[t] - b.delta_root[t]).norm(), 0.0, 1e-12);
    EXPECT_NEAR(a.delta_log_scale[t], b.delta_log_scale[t], 1e-12);
  }
  EXPECT_NEAR(b.first_scale_px, zoom * a.first_scale_px, 1e-9);
  EXPECT_NEAR((b.first_root_px - (zoom * a.first_root_px + shift)).norm(), 0.0,
              1e-9);
}

TEST(Canonical, FramesWithoutRootCarryThePreviousOne) {
  // Frame 0: nothing; frame 1: a body; frame 2: hips gone; frame 3: moved.
  Clip2D clip;
  clip.keypoints = KeypointTrack(4, kJ);
  for (int j = 0; j < kJ; ++j) clip.keypoints.at(0, j) = Missing();
  for (int t = 1; t < 4; ++t) {
    const double dx = t == 3 ? 30.0 : 0.0;
    for (int j = 0; j < kJ; ++j) {
      clip.keypoints.at(t, j) = {100.0 + dx + 5.0 * j, 300.0 - 9.0 * j, 1.0};
    }
  }
  clip.keypoints.at(2, kLeftHip) = Missing();
  clip.keypoints.at(2, kRightHip) = Missing();

  CanonicalClip canonical = ToCanonical(clip);
  Eigen::Vector2d root1;
  double scale1 = 0.0;
  ASSERT_TRUE(
      RootAndScale(clip.keypoints.frame(1), Coco17Layout(), &root1, &scale1));
  // The leading empty frame takes frame 1's root and scale.
  EXPECT_EQ(canonical.first_root_px, root1);
  EXPECT_EQ(canonical.first_scale_px, scale1);
  for (int t = 0; t < 3; ++t) {
    EXPECT_EQ(canonical.delta_root[t], Eigen::Vector2d::Zero()) << t;
    EXPECT_EQ(canonical.delta_log_scale[t], 0.0) << t;
  }
  // Frame 2 is expressed in frame 1's root/scale; frame 3 stepped 30 px.
  EXPECT_NEAR(canonical.local_pose.at(2, 0).x_px,
              (clip.keypoints.at(2, 0).x_px - root1.x()) / scale1, 1e-15);
  EXPECT_NEAR(canonical.delta_root[3].x(), 30.0 / scale1, 1e-12);
  EXPECT_NEAR(canonical.delta_root[3].y(), 0.0, 1e-12);
  EXPECT_NEAR(canonical.delta_log_scale[3], 0.0, 1e-12);
}

TEST(Canonical, AllMissingClipIsAnError) {
  Clip2D clip;
  clip.keypoints = KeypointTrack(3, kJ);
  for (int t = 0; t < 3; ++t) {
    for (int j = 0; j < kJ; ++j) clip.keypoints.at(t, j) = Missing();
  }
  try {
    ToCanonical(clip, "empty.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("empty.json: no frame has a root"),
              std::string::npos)
        << error.what();
  }
}

TEST(Canonical, InconsistentCanonicalClipIsAnError) {
  CanonicalClip canonical = ToCanonical(RandomClip(4, 10));
  canonical.delta_root.pop_back();
  EXPECT_THROW(FromCanonical(canonical), InputError);
  canonical = ToCanonical(RandomClip(4, 10));
  canonical.first_scale_px = 0.0;
  EXPECT_THROW(FromCanonical(canonical), InputError);
}

}  // namespace
}  // namespace m2d
