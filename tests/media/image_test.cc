#include "media/image.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "media/media_test_util.h"

namespace m2d {
namespace {

// Pixel (x, y) holds (5x, 10y, 77): a position readable from the colour.
RgbImage Ramp(int width_px, int height_px) {
  RgbImage image(width_px, height_px);
  for (int y = 0; y < height_px; ++y) {
    for (int x = 0; x < width_px; ++x) {
      image.set(
          x, y,
          {static_cast<uint8_t>(5 * x), static_cast<uint8_t>(10 * y), 77});
    }
  }
  return image;
}

TEST(CropAndScale, AtScaleOneCopiesTheWindow) {
  const RgbImage source = Ramp(40, 20);
  const RgbImage window = CropAndScale(source, 10, 5, 1.0, 20, 10);
  ASSERT_EQ(window.width_px(), 20);
  ASSERT_EQ(window.height_px(), 10);
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 20; ++u) {
      EXPECT_LE(
          testing::ColorDistance(window.at(u, v), source.at(u + 10, v + 5)), 1)
          << u << ", " << v;
    }
  }
}

TEST(CropAndScale, MagnifiesAroundTheCorner) {
  const RgbImage source = Ramp(40, 20);
  // Twice as large: output pixel (2u + 1, 2v + 1) has its centre at source
  // point (10 + u + 0.75, 5 + v + 0.75), between source pixels (10 + u,
  // 5 + v) and the next: within one ramp step of the first.
  const RgbImage zoomed = CropAndScale(source, 10, 5, 2.0, 40, 20);
  for (int v = 0; v < 9; ++v) {
    for (int u = 0; u < 19; ++u) {
      const Rgb got = zoomed.at(2 * u + 1, 2 * v + 1);
      const Rgb near = source.at(10 + u, 5 + v);
      EXPECT_GE(got.r, near.r);
      EXPECT_LE(got.r, near.r + 5);
      EXPECT_GE(got.g, near.g);
      EXPECT_LE(got.g, near.g + 10);
      EXPECT_NEAR(got.b, 77, 1);
    }
  }
}

TEST(CropAndScale, OutsideTheSourceIsBlack) {
  const RgbImage source(10, 10, Rgb{200, 200, 200});
  const RgbImage window = CropAndScale(source, -10, 0, 1.0, 20, 10);
  EXPECT_EQ(window.at(2, 5), (Rgb{0, 0, 0}));
  EXPECT_EQ(window.at(15, 5), (Rgb{200, 200, 200}));
  EXPECT_THROW(CropAndScale(source, 0, 0, 0.0, 20, 10), std::invalid_argument);
  EXPECT_THROW(CropAndScale(RgbImage(), 0, 0, 1.0, 20, 10),
               std::invalid_argument);
}

}  // namespace
}  // namespace m2d
