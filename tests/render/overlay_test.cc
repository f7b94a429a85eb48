#include "render/overlay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "render_test_util.h"

namespace m2d {
namespace {

constexpr Rgb kGray = {128, 128, 128};
constexpr Rgb kRed = {230, 50, 40};

std::vector<Keypoint2D> StandingFigure() {
  // COCO-17 in a 400x300 image, at fractional pixel positions.
  std::vector<Keypoint2D> points(17);
  const double xy[17][2] = {{200.3, 60.7},    {195.5, 55.2},  {205.5, 55.2},
                            {190.1, 58.0},    {210.9, 58.0},  {180.4, 90.6},
                            {220.6, 90.6},    {170.2, 130.3}, {230.8, 130.3},
                            {165.5, 165.5},   {235.5, 165.5}, {188.25, 170.75},
                            {212.75, 170.75}, {186.4, 220.1}, {214.6, 220.1},
                            {185.9, 270.6},   {215.1, 270.6}};
  for (int j = 0; j < 17; ++j) points[j] = {xy[j][0], xy[j][1], 1.0};
  return points;
}

TEST(OverlayCanvas, DotsAndBonesLandOnTheirPixels) {
  RgbImage image(400, 300, kGray);
  const std::vector<Keypoint2D> points = StandingFigure();
  OverlayCanvas canvas(&image);
  canvas.DrawSkeleton(Coco17Layout(), points, kRed, OverlaySizes{2, 3, 12});
  canvas.Finish();
  // The pixel holding each keypoint is exactly the skeleton colour.
  for (const Keypoint2D& point : points) {
    EXPECT_EQ(image.at(static_cast<int>(std::floor(point.x_px)),
                       static_cast<int>(std::floor(point.y_px))),
              kRed)
        << point.x_px << ", " << point.y_px;
  }
  // The middle of the left shin (a bone) is drawn; a corner is not.
  const Keypoint2D& knee = points[static_cast<int>(Coco17::kLeftKnee)];
  const Keypoint2D& ankle = points[static_cast<int>(Coco17::kLeftAnkle)];
  EXPECT_EQ(image.at(static_cast<int>((knee.x_px + ankle.x_px) / 2),
                     static_cast<int>((knee.y_px + ankle.y_px) / 2)),
            kRed);
  EXPECT_EQ(image.at(10, 290), kGray);
  // Nothing is drawn beyond the dots' and lines' reach.
  int changed = 0;
  for (int y = 0; y < 300; ++y) {
    for (int x = 0; x < 400; ++x) changed += image.at(x, y) != kGray;
  }
  EXPECT_GT(changed, 400);
  EXPECT_LT(changed, 6000);
}

TEST(OverlayCanvas, ARingCirclesItsPointAndAMissingPointDrawsNothing) {
  RgbImage image(400, 300, kGray);
  OverlayCanvas canvas(&image);
  canvas.DrawRing({200.5, 150.5, 1.0}, 40.0, kRed, OverlaySizes{4, 3, 12});
  canvas.DrawRing({100.5, 100.5, 0.0}, 40.0, kRed, OverlaySizes{4, 3, 12});
  canvas.Finish();
  // On the circle: the colour; its centre and the missing point's: not.
  EXPECT_EQ(image.at(240, 150), kRed);
  EXPECT_EQ(image.at(160, 150), kRed);
  EXPECT_EQ(image.at(200, 110), kRed);
  EXPECT_EQ(image.at(200, 150), kGray);
  EXPECT_EQ(image.at(60, 100), kGray);
  EXPECT_EQ(image.at(100, 100), kGray);
}

TEST(OverlayCanvas, MissingKeypointsAndTheirBonesAreSkipped) {
  std::vector<Keypoint2D> points = StandingFigure();
  Keypoint2D& wrist = points[static_cast<int>(Coco17::kRightWrist)];
  const int u = static_cast<int>(wrist.x_px), v = static_cast<int>(wrist.y_px);
  wrist.confidence = 0.0;
  points[static_cast<int>(Coco17::kLeftWrist)].x_px =
      std::numeric_limits<double>::quiet_NaN();
  RgbImage image(400, 300, kGray);
  OverlayCanvas canvas(&image);
  canvas.DrawSkeleton(Coco17Layout(), points, kRed, OverlaySizes{2, 3, 12});
  canvas.Finish();
  EXPECT_EQ(image.at(u, v), kGray);
  // The right forearm's midpoint (elbow to the missing wrist) is not drawn.
  const Keypoint2D& elbow = points[static_cast<int>(Coco17::kRightElbow)];
  EXPECT_EQ(image.at(static_cast<int>((elbow.x_px + wrist.x_px) / 2),
                     static_cast<int>((elbow.y_px + wrist.y_px) / 2)),
            kGray);
}

TEST(OverlayCanvas, LabelDrawsTextInTheCorner) {
  RgbImage image(400, 300, kGray);
  OverlayCanvas canvas(&image);
  canvas.DrawLabel({{"frame 12"}, {"E2D 3.4 px"}, {"reference", kRed, true}}, 6,
                   6, OverlaySizesForHeight(300));
  canvas.Finish();
  int dark = 0, white = 0, red = 0, changed_elsewhere = 0;
  for (int y = 0; y < 300; ++y) {
    for (int x = 0; x < 400; ++x) {
      const Rgb pixel = image.at(x, y);
      if (x < 200 && y < 100) {
        dark += pixel.r < 80 && pixel.g < 80;
        white += pixel.r > 200 && pixel.g > 200 && pixel.b > 200;
        red += pixel == kRed;
      } else {
        changed_elsewhere += pixel != kGray;
      }
    }
  }
  EXPECT_GT(dark, 500);  // the box
  EXPECT_GT(white, 50);  // the text
  EXPECT_GT(red, 10);    // the legend swatch
  EXPECT_EQ(changed_elsewhere, 0);
}

TEST(Png, RoundTripsThroughCairo) {
  RgbImage image(31, 17, {10, 20, 30});
  image.set(30, 16, {250, 1, 128});
  const std::string path = testing::TempDir("png_round_trip") + "/x.png";
  WritePng(path, image);
  const testing::PngSize size = testing::ReadPngSize(path);
  EXPECT_EQ(size.width_px, 31);
  EXPECT_EQ(size.height_px, 17);
  const RgbImage back = ReadPng(path);
  EXPECT_EQ(back.at(0, 0), (Rgb{10, 20, 30}));
  EXPECT_EQ(back.at(30, 16), (Rgb{250, 1, 128}));
  EXPECT_THROW(ReadPng(path + ".missing"), InputError);
}

}  // namespace
}  // namespace m2d
