#include "detect/movenet.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "media/video_reader.h"
#include "test_paths.h"

namespace m2d {
namespace {

const std::string kMedia = "/usr/share/doc/opencv-doc/examples/data/";

// Positions read by eye off messi5.jpg (548x342, the player about 250 px
// tall, facing the camera: his left is the image's right), COCO-17 index
// and pixel.
struct HandChecked {
  int index;
  double x_px, y_px;
  const char* name;
};
const HandChecked kMessi[] = {
    {0, 248, 112, "nose"},        {9, 362, 162, "left wrist"},
    {11, 295, 222, "left hip"},   {12, 245, 238, "right hip"},
    {15, 415, 262, "left ankle"}, {16, 278, 310, "right ankle"}};
constexpr double kTolerancePx = 25.0;

// Every hand-checked point within `tolerance_px` (the ankles, the hardest,
// within `ankle_tolerance_px`) and at least `min_confidence`.
void ExpectOnThePlayer(const DetectedPerson& person, double min_confidence,
                       double ankle_tolerance_px = kTolerancePx) {
  for (const HandChecked& point : kMessi) {
    const Keypoint2D& k = person.keypoints[point.index];
    const bool ankle = point.index >= 15;
    EXPECT_LT(std::hypot(k.x_px - point.x_px, k.y_px - point.y_px),
              ankle ? ankle_tolerance_px : kTolerancePx)
        << point.name << " at " << k.x_px << ", " << k.y_px;
    EXPECT_GT(k.confidence, min_confidence) << point.name;
  }
}

// Single pose on the whole photo and MultiPose's best person land on the
// player. Measured: Thunder within 25 px everywhere (scores >= 0.39);
// Lightning puts the left ankle 29 px off (score 0.21); MultiPose's best
// person scores its ankles 0.17.
TEST(MoveNet, KeypointsLandOnThePersonInAPhoto) {
  RgbImage image = ReadImageFile(kMedia + "messi5.jpg");
  {
    SCOPED_TRACE("thunder");
    MoveNet thunder(DefaultMoveNetFolder(), MoveNetModel::kThunder);
    ExpectOnThePlayer(thunder.DetectInRegion(image, 274, 171, 548), 0.3);
  }
  MoveNet lightning(DefaultMoveNetFolder(), MoveNetModel::kLightning);
  {
    SCOPED_TRACE("lightning");
    ExpectOnThePlayer(lightning.DetectInRegion(image, 274, 171, 548), 0.15,
                      40.0);
  }
  SCOPED_TRACE("multipose");
  std::vector<DetectedPerson> people = lightning.DetectPeople(image, 512);
  ASSERT_FALSE(people.empty());
  const Box& box = people[0].box;
  EXPECT_LT(box.x0_px, 248);
  EXPECT_GT(box.x1_px, 415);
  ExpectOnThePlayer(people[0], 0.1);
}

// A region partly outside the image: the rest is black and the keypoints
// still come back in image pixels.
TEST(MoveNet, ARegionLeavingTheImageMapsBackToImagePixels) {
  RgbImage image = ReadImageFile(kMedia + "messi5.jpg");
  MoveNet movenet(DefaultMoveNetFolder(), MoveNetModel::kThunder);
  DetectedPerson shifted = movenet.DetectInRegion(image, 300, 200, 400);
  EXPECT_LT(std::hypot(shifted.keypoints[0].x_px - 248,
                       shifted.keypoints[0].y_px - 112),
            kTolerancePx);
}

TEST(MoveNet, AMissingModelFolderIsNamed) {
  const std::string folder = testing::TempDir("movenet_missing");
  try {
    MoveNet movenet(folder, MoveNetModel::kLightning);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(error.source().find(folder), std::string::npos);
  }
}

TEST(Box, IouOfOverlappingDisjointAndEmptyBoxes) {
  EXPECT_DOUBLE_EQ(BoxIou({0, 0, 2, 2}, {1, 0, 3, 2}), 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(BoxIou({0, 0, 1, 1}, {2, 2, 3, 3}), 0.0);
  EXPECT_DOUBLE_EQ(BoxIou({0, 0, 0, 0}, {0, 0, 0, 0}), 0.0);
}

}  // namespace
}  // namespace m2d
