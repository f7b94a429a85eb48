#include "render/episode_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "common/error.h"
#include "env/env_fixture.h"
#include "render_test_util.h"

namespace m2d {
namespace {

constexpr char kWalk[] = "deepmimic/motions/humanoid3d_walk.txt";

// The humanoid in its reference pose, seen by a 640x480 camera.
class EpisodeFrameTest : public ::testing::Test {
 protected:
  void SetUp() override {
    character_ = testing::LoadRenderHumanoid();
    Simulation simulation(character_, SimulationOptions());
    state_ = simulation.Save();
    keypoints_m_ = SimulatedKeypoints(simulation);
    const Eigen::Vector3d center = testing::Centroid(keypoints_m_);
    Intrinsics intrinsics;
    intrinsics.width_px = 640;
    intrinsics.height_px = 480;
    intrinsics.fx_px = intrinsics.fy_px = 600.0;
    intrinsics.cx_px = 330.0;
    intrinsics.cy_px = 250.0;
    camera_ = PinholeCamera::LookAt(
        intrinsics, center + Eigen::Vector3d(3.0, 1.5, 0.4), center);
  }

  // The pose's keypoints projected, shifted by `shift_px` horizontally.
  std::vector<Keypoint2D> Projected(double shift_px) const {
    std::vector<Keypoint2D> points;
    for (const Eigen::Vector3d& keypoint : keypoints_m_) {
      const Eigen::Vector2d pixel = camera_.Project(keypoint).pixel_px;
      points.push_back({pixel.x() + shift_px, pixel.y(), 1.0});
    }
    return points;
  }

  std::shared_ptr<const Character> character_;
  SimState state_;
  std::vector<Eigen::Vector3d> keypoints_m_;
  PinholeCamera camera_;
};

TEST_F(EpisodeFrameTest, OverlaysLandOnTheProjectedAndReferencePixels) {
  EpisodeRenderOptions options;
  options.scale = 0.5;
  EpisodeRenderer renderer(character_, SimulationOptions(),
                           character_->keypoint_layout(), 640, 480, options);
  EXPECT_EQ(renderer.width_px(), 320);
  EXPECT_EQ(renderer.height_px(), 240);

  // The character with a reference 30 px (clip pixels) to its right.
  EpisodeFrame frame;
  frame.clip_frame = 7;
  frame.camera = camera_;
  frame.state = state_;
  frame.reference = Projected(30.0);
  const RenderedFrame rendered = renderer.Render(frame);
  ASSERT_EQ(rendered.image.width_px(), 320);
  EXPECT_NEAR(rendered.e2d_px, 30.0, 1e-9);
  // Every projected keypoint's pixel (at half scale) is the pose colour,
  // drawn over the 3D render and the reference.
  for (const Keypoint2D& point : Projected(0.0)) {
    EXPECT_EQ(rendered.image.at(static_cast<int>(std::floor(0.5 * point.x_px)),
                                static_cast<int>(std::floor(0.5 * point.y_px))),
              options.pose_color);
  }

  // Without a pose, the reference alone is drawn, at its pixels.
  EpisodeFrame reference_only = frame;
  reference_only.state.reset();
  const RenderedFrame drawn = renderer.Render(reference_only);
  EXPECT_TRUE(std::isnan(drawn.e2d_px));
  for (const Keypoint2D& point : frame.reference) {
    EXPECT_EQ(drawn.image.at(static_cast<int>(std::floor(0.5 * point.x_px)),
                             static_cast<int>(std::floor(0.5 * point.y_px))),
              options.reference_color);
  }
}

// With a ball tracked: the reference's ball (green) and the simulated ball
// (red) are rings a ball's size around their centres.
TEST_F(EpisodeFrameTest, TrackedObjectsAreRingsAroundTheirCentres) {
  auto character = LoadCharacterForSimulation(
      testing::SourcePath("assets/characters/humanoid.yaml"), "ball",
      SimulationOptions());
  Simulation simulation(character, SimulationOptions());
  const double* ball =
      simulation.data()->xpos + 3 * character->free_objects()[0].body_id;
  const Projection projection = camera_.Project({ball[0], ball[1], ball[2]});
  const double radius_px = 600.0 * 0.11 / projection.depth_m;
  EpisodeRenderOptions options;
  options.subject_height_fraction = 0.0;  // no zoom: clip pixels are shown
  EpisodeRenderer renderer(character, SimulationOptions(),
                           character->keypoint_layout(), 640, 480, options);
  EpisodeFrame frame;
  frame.camera = camera_;
  frame.state = simulation.Save();
  // The reference ball 120 px left of the simulated one.
  frame.reference_objects = {
      {projection.pixel_px.x() - 120.0, projection.pixel_px.y(), 1.0}};
  const RenderedFrame rendered = renderer.Render(frame);
  const int y = static_cast<int>(std::floor(projection.pixel_px.y()));
  EXPECT_EQ(
      rendered.image.at(
          static_cast<int>(std::floor(projection.pixel_px.x() + radius_px)), y),
      options.pose_color);
  // The reference ring is drawn wider, just outside the ball's size: some
  // pixel within 10 px outside that radius is its colour; its centre is not.
  const double reference_x = projection.pixel_px.x() - 120.0;
  bool ring = false;
  for (int dx = 0; dx <= 10; ++dx) {
    const int x = static_cast<int>(std::floor(reference_x - radius_px - dx));
    ring = ring || rendered.image.at(x, y) == options.reference_color;
  }
  EXPECT_TRUE(ring);
  EXPECT_NE(rendered.image.at(static_cast<int>(std::floor(reference_x)), y),
            options.reference_color);
}

// A subject far from the camera: the view zooms in until it fills half
// the frame height, and the overlays follow the crop.
TEST_F(EpisodeFrameTest, FramingZoomsInOnASmallSubject) {
  const Eigen::Vector3d center = testing::Centroid(keypoints_m_);
  Intrinsics intrinsics = camera_.intrinsics();
  camera_ = PinholeCamera::LookAt(
      intrinsics, center + Eigen::Vector3d(9.0, 4.5, 1.2), center);
  EpisodeRenderOptions options;
  options.scale = 0.5;
  options.subject_height_fraction = 0.5;
  EpisodeRenderer renderer(character_, SimulationOptions(),
                           character_->keypoint_layout(), 640, 480, options);
  EpisodeFrame frame;
  frame.camera = camera_;
  frame.state = state_;
  frame.reference = Projected(0.0);
  const RenderedFrame rendered = renderer.Render(frame);
  EXPECT_GT(rendered.zoom, 1.5);
  EXPECT_NEAR(rendered.e2d_px, 0.0, 1e-9);  // measured in clip pixels
  double top = 1e9, bottom = -1e9;
  for (const Keypoint2D& point : frame.reference) {
    const Eigen::Vector2d shown =
        (point.Pixel() - rendered.crop_corner_px) * rendered.zoom * 0.5;
    top = std::min(top, shown.y());
    bottom = std::max(bottom, shown.y());
    ASSERT_GE(shown.x(), 0);
    ASSERT_LT(shown.x(), 320);
    EXPECT_EQ(rendered.image.at(static_cast<int>(std::floor(shown.x())),
                                static_cast<int>(std::floor(shown.y()))),
              options.pose_color);
  }
  EXPECT_NEAR((bottom - top) / 240.0, 0.5, 1e-6);

  // Framing off: the camera's whole image.
  options.subject_height_fraction = 0.0;
  EpisodeRenderer whole(character_, SimulationOptions(),
                        character_->keypoint_layout(), 640, 480, options);
  EXPECT_EQ(whole.Render(frame).zoom, 1.0);
}

TEST_F(EpisodeFrameTest, SideCameraDoublesTheWidth) {
  EpisodeRenderOptions options;
  options.scale = 0.5;
  options.side_camera = true;
  EpisodeRenderer renderer(character_, SimulationOptions(),
                           character_->keypoint_layout(), 640, 480, options);
  EpisodeFrame frame;
  frame.camera = camera_;
  frame.state = state_;
  const RenderedFrame rendered = renderer.Render(frame);
  EXPECT_EQ(rendered.image.width_px(), 640);
  EXPECT_EQ(rendered.image.height_px(), 240);
  // The right panel is the orbit camera around the pose's centre, with the
  // pose's keypoints drawn where that camera projects them.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& keypoint : keypoints_m_) center += keypoint;
  const PinholeCamera side =
      OrbitCamera(options.side, center / keypoints_m_.size(), 320, 240);
  for (const Eigen::Vector3d& keypoint : keypoints_m_) {
    const Eigen::Vector2d pixel = side.Project(keypoint).pixel_px;
    EXPECT_EQ(rendered.image.at(320 + static_cast<int>(std::floor(pixel.x())),
                                static_cast<int>(std::floor(pixel.y()))),
              options.pose_color);
  }
}

TEST_F(EpisodeFrameTest, SourcePanelShowsTheRecordingUnderTheSameFraming) {
  EpisodeRenderOptions options;
  options.scale = 0.5;
  options.source_panel = true;
  options.subject_height_fraction = 0.0;  // the whole image: zoom 1
  EpisodeRenderer renderer(character_, SimulationOptions(),
                           character_->keypoint_layout(), 640, 480, options);
  EXPECT_EQ(renderer.width_px(), 640);
  EpisodeFrame frame;
  frame.camera = camera_;
  frame.state = state_;
  // The recording: blue left half, yellow right half.
  frame.source_image = RgbImage(640, 480, Rgb{20, 40, 200});
  for (int y = 0; y < 480; ++y) {
    for (int x = 320; x < 640; ++x)
      frame.source_image.set(x, y, {220, 210, 30});
  }
  const RenderedFrame rendered = renderer.Render(frame);
  ASSERT_EQ(rendered.image.width_px(), 640);
  ASSERT_EQ(rendered.image.height_px(), 240);
  // Left panel (320 x 240): the recording at half size, away from the
  // label in the top-left corner and the seam.
  EXPECT_LE(testing::ColorDistance(rendered.image.at(100, 200), {20, 40, 200}),
            2);
  EXPECT_LE(testing::ColorDistance(rendered.image.at(250, 200), {220, 210, 30}),
            2);
  // Right panel: the render, the same as without the recording.
  options.source_panel = false;
  EpisodeRenderer alone(character_, SimulationOptions(),
                        character_->keypoint_layout(), 640, 480, options);
  const RenderedFrame render = alone.Render(frame);
  int differing = 0;
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      differing += rendered.image.at(320 + x, y) != render.image.at(x, y);
    }
  }
  EXPECT_EQ(differing, 0);
  // A frame without the recording, or at another size, is named.
  frame.source_image = RgbImage();
  EXPECT_THROW(renderer.Render(frame), InputError);
  frame.source_image = RgbImage(320, 240);
  EXPECT_THROW(renderer.Render(frame), InputError);
}

TEST_F(EpisodeFrameTest, MismatchedFramesAreInputErrors) {
  EpisodeRenderer renderer(character_, SimulationOptions(),
                           character_->keypoint_layout(), 640, 480,
                           EpisodeRenderOptions());
  EpisodeFrame frame;
  frame.camera = camera_;
  frame.state = state_;
  frame.reference = Projected(0.0);
  frame.reference.pop_back();
  EXPECT_THROW(renderer.Render(frame), InputError);
  EpisodeRenderer wrong_size(character_, SimulationOptions(),
                             character_->keypoint_layout(), 1920, 1080,
                             EpisodeRenderOptions());
  frame.reference.clear();
  EXPECT_THROW(wrong_size.Render(frame), InputError);
}

TEST(BundleReplay, WalkVideoPngsAndFrameRange) {
  M2D_REQUIRE_SHARED(motion_path, kWalk);
  auto character = testing::LoadRenderHumanoid();
  const ReferenceBundle bundle =
      testing::MakeWalkBundle(motion_path, *character, 1.0);
  const std::string folder = testing::TempDir("bundle_replay");
  BundleReplayOptions options;
  options.character_config =
      testing::SourcePath("assets/characters/humanoid.yaml");
  options.view = bundle.views[1].name;
  options.render.scale = 0.25;
  options.render.side_camera = true;
  options.output.video_path = folder + "/walk.mp4";
  options.output.png_folder = folder + "/frames";
  options.output.first_frame = 3;
  options.output.last_frame = 12;
  const EpisodeSummary summary = RenderBundleReplay(bundle, options);

  EXPECT_EQ(summary.frames_rendered, 10);
  EXPECT_EQ(summary.width_px, 960);  // two 480x270 panels
  EXPECT_EQ(summary.height_px, 270);
  // Ground truth replayed: the character's keypoints are the reference.
  EXPECT_LT(summary.mean_e2d_px, 1.0);

  const testing::VideoInfo video = testing::ProbeVideo(summary.video_path);
  EXPECT_EQ(video.frames, 10);
  EXPECT_EQ(video.width_px, 960);
  EXPECT_EQ(video.height_px, 270);
  ASSERT_EQ(summary.png_paths.size(), 10u);
  EXPECT_EQ(std::filesystem::path(summary.png_paths.front()).filename(),
            "frame_000003.png");
  EXPECT_EQ(std::filesystem::path(summary.png_paths.back()).filename(),
            "frame_000012.png");
  const testing::PngSize png = testing::ReadPngSize(summary.png_paths[4]);
  EXPECT_EQ(png.width_px, 960);
  EXPECT_EQ(png.height_px, 270);

  options.view = "no such view";
  EXPECT_THROW(RenderBundleReplay(bundle, options), InputError);
  options.view.clear();
  options.output.first_frame = 40;
  options.output.last_frame = -1;
  EXPECT_THROW(RenderBundleReplay(bundle, options), ConfigError);
}

TEST(BundleReplay, SkeletonWithoutCharacterShowsTheGroundTruth) {
  M2D_REQUIRE_SHARED(motion_path, kWalk);
  auto character = testing::LoadRenderHumanoid();
  ReferenceBundle bundle =
      testing::MakeWalkBundle(motion_path, *character, 0.5);
  bundle.ground_truth->skeleton_name = "a skeleton with no character";
  BundleReplaySource source(bundle, 0, character, SimulationOptions());
  EXPECT_FALSE(source.shows_character());
  EpisodeFrame frame;
  ASSERT_TRUE(source.Next(&frame));
  EXPECT_FALSE(frame.state.has_value());
  EXPECT_EQ(frame.keypoints_world_m.size(), 17u);

  BundleReplayOptions options;
  options.character_config =
      testing::SourcePath("assets/characters/humanoid.yaml");
  options.render.scale = 0.25;
  options.output.video_path = testing::TempDir("truth_replay") + "/truth.mp4";
  options.output.last_frame = 4;
  const EpisodeSummary summary = RenderBundleReplay(bundle, options);
  EXPECT_EQ(summary.frames_rendered, 5);
  // The reference is the ground truth's exact projection.
  EXPECT_LT(summary.mean_e2d_px, 1e-6);
  EXPECT_EQ(testing::ProbeVideo(summary.video_path).frames, 5);
}

// A fitted bundle replays its estimate: the fitted pose under the fitted
// camera, with no truth left. The estimate here is the truth moved into
// it (a perfect fit), shifted by 0.1 m in depth on frame 2 to show that the
// estimate, not something else, is drawn.
TEST(BundleReplay, AFittedBundleReplaysItsEstimate) {
  M2D_REQUIRE_SHARED(motion_path, kWalk);
  auto character = testing::LoadRenderHumanoid();
  ReferenceBundle bundle =
      testing::MakeWalkBundle(motion_path, *character, 0.5);
  BundleReplayOptions options;
  options.character_config =
      testing::SourcePath("assets/characters/humanoid.yaml");
  options.motion = ReplayedMotion::kEstimate;
  options.render.scale = 0.25;
  options.output.video_path = testing::TempDir("estimate_replay") + "/fit.mp4";
  options.output.last_frame = 4;
  // Not fitted yet: a named error.
  EXPECT_THROW(RenderBundleReplay(bundle, options), InputError);

  std::vector<ViewEstimate> estimates;
  for (const ReferenceView& view : bundle.views) {
    ViewEstimate estimate;
    estimate.cameras = view.cameras;
    estimate.skeleton_name = bundle.ground_truth->skeleton_name;
    estimate.poses = bundle.ground_truth->poses;
    estimate.residual_px.assign(bundle.num_frames(), 0.0);
    estimates.push_back(estimate);
  }
  estimates[0].poses[2].root_position_m.x() += 0.1;
  bundle.estimate = estimates;
  bundle.ground_truth.reset();
  for (ReferenceView& view : bundle.views) view.cameras.clear();  // stripped
  const EpisodeSummary summary = RenderBundleReplay(bundle, options);
  EXPECT_EQ(summary.frames_rendered, 5);
  // Four frames exact, one off by the shift.
  EXPECT_GT(summary.mean_e2d_px, 0.1);
  EXPECT_LT(summary.mean_e2d_px, 10.0);
  estimates[0].poses[2].root_position_m.x() -= 0.1;
  bundle.estimate = estimates;
  EXPECT_LT(RenderBundleReplay(bundle, options).mean_e2d_px, 1e-6);
}

TEST(SourceVideoFrames, AClipFrameShowsTheVideoFrameOfItsMoment) {
  // A 10 fps video whose frame k is grey level 20 k, and a 30 Hz clip of
  // 13 frames starting 0.1 s into it: clip frame t is at 0.1 + t / 30 s,
  // video frame 1 + t / 3; past the video's last frame (5), it stays.
  const std::string path = testing::TempDir("source_video") + "/10fps.mp4";
  Mp4Options video;
  video.fps = 10.0;
  video.crf = 0;
  {
    Mp4Writer writer(path, 64, 48, video);
    for (int k = 0; k < 6; ++k) {
      const uint8_t level = static_cast<uint8_t>(20 * k + 30);
      writer.Write(RgbImage(64, 48, Rgb{level, level, level}));
    }
    writer.Finish();
  }
  std::vector<EpisodeFrame> clip(13);
  for (int t = 0; t < 13; ++t) clip[t].clip_frame = t;
  RecordedFrames recorded(clip);
  SourceVideoFrames with_video(recorded, path, 30.0, 0.1);
  EpisodeFrame frame;
  for (int t = 0; t < 13; ++t) {
    ASSERT_TRUE(with_video.Next(&frame));
    ASSERT_EQ(frame.source_image.width_px(), 64);
    const int k = std::min(1 + t / 3, 5);
    EXPECT_NEAR(frame.source_image.at(32, 24).g, 20 * k + 30, 3) << "t " << t;
  }
  EXPECT_FALSE(with_video.Next(&frame));
  // Not a video: named.
  RecordedFrames again(clip);
  EXPECT_THROW(
      SourceVideoFrames(again, testing::SourcePath("README.md"), 30.0, 0.0),
      InputError);
}

}  // namespace
}  // namespace m2d
