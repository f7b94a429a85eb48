#include "camera/rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "camera/camera_io.h"
#include "common/error.h"
#include "test_paths.h"

namespace m2d {
namespace {

TEST(Rig, ViewsCircleTheTargetAtTheGivenDistanceAndElevation) {
  RigOptions options;
  options.num_views = 4;
  options.distance_m = 4.5;
  options.elevation_deg = 10;
  std::vector<NamedCamera> rig = MakeRig(options);
  ASSERT_EQ(rig.size(), 4u);
  for (size_t k = 0; k < rig.size(); ++k) {
    const PinholeCamera& camera = rig[k].camera;
    Eigen::Vector3d offset = camera.CenterWorld() - options.target_m;
    EXPECT_NEAR(offset.norm(), 4.5, 1e-9);
    EXPECT_NEAR(std::asin(offset.z() / offset.norm()) * 180 / M_PI, 10.0, 1e-9);
    Projection centre = camera.Project(options.target_m);
    EXPECT_NEAR(centre.pixel_px.x(), 960, 1e-9);
    EXPECT_NEAR(centre.pixel_px.y(), 540, 1e-9);
    EXPECT_EQ(rig[k].name, "view" + std::to_string(k));
  }
  // Evenly spread: consecutive views are 90 degrees apart in azimuth.
  Eigen::Vector3d a = rig[0].camera.CenterWorld() - options.target_m;
  Eigen::Vector3d b = rig[1].camera.CenterWorld() - options.target_m;
  a.z() = b.z() = 0;
  EXPECT_NEAR(std::acos(a.normalized().dot(b.normalized())) * 180 / M_PI, 90,
              1e-9);
}

// An AIST++-like rig: the views differ in elevation and range as well.
TEST(Rig, SpansSpreadElevationAndDistanceOverTheViews) {
  RigOptions options;
  options.num_views = 4;
  options.elevation_deg = 30;
  options.elevation_span_deg = -30;
  options.distance_m = 3.5;
  options.distance_span_m = 2.5;
  std::vector<NamedCamera> rig = MakeRig(options);
  const double elevations[] = {30, 20, 10, 0};
  const double distances[] = {3.5, 3.5 + 2.5 / 3, 3.5 + 5.0 / 3, 6.0};
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector3d offset = rig[k].camera.CenterWorld() - options.target_m;
    EXPECT_NEAR(offset.norm(), distances[k], 1e-9);
    EXPECT_NEAR(std::asin(offset.z() / offset.norm()) * 180 / M_PI,
                elevations[k], 1e-9);
  }
  options.elevation_span_deg = 60;  // the last view at 90 degrees
  EXPECT_THROW(MakeRig(options), ConfigError);
  options.elevation_span_deg = 0;
  options.distance_span_m = -3.45;  // the last view 5 cm from the target
  EXPECT_THROW(MakeRig(options), ConfigError);
}

TEST(Rig, ValidateRejectsBadSettings) {
  RigOptions options;
  options.num_views = 0;
  EXPECT_THROW(MakeRig(options), ConfigError);
  options = RigOptions();
  options.distance_m = 0;
  EXPECT_THROW(MakeRig(options), ConfigError);
  options = RigOptions();
  options.elevation_deg = 90;
  EXPECT_THROW(MakeRig(options), ConfigError);
  // Found by fuzzing: 100000 views ran out of memory (abort); a NaN azimuth
  // made a bundle whose keypoints were all missing.
  options = RigOptions();
  options.num_views = 100000;
  EXPECT_THROW(MakeRig(options), ConfigError);
  options = RigOptions();
  options.first_azimuth_deg = std::nan("");
  EXPECT_THROW(MakeRig(options), ConfigError);
  options = RigOptions();
  options.focal_px = std::numeric_limits<double>::infinity();
  EXPECT_THROW(MakeRig(options), ConfigError);
  options = RigOptions();
  options.width_px = 1 << 20;
  EXPECT_THROW(MakeRig(options), ConfigError);
}

TEST(CameraIo, CameraSetRoundTrips) {
  std::string dir = testing::TempDir("camera_io");
  std::vector<NamedCamera> rig = MakeRig(RigOptions());
  std::string path = dir + "/cameras.json";
  WriteCameraSet(path, rig);
  std::vector<NamedCamera> read = ReadCameraSet(path);
  ASSERT_EQ(read.size(), rig.size());
  for (size_t k = 0; k < rig.size(); ++k) {
    EXPECT_EQ(read[k].name, rig[k].name);
    Eigen::Vector3d point(0.1, 0.2, 1.0);
    EXPECT_LT((read[k].camera.Project(point).pixel_px -
               rig[k].camera.Project(point).pixel_px)
                  .norm(),
              1e-9);
  }
}

void ExpectCameraFileError(const std::string& text, const std::string& needle) {
  std::string dir = testing::TempDir("camera_bad");
  std::string path = dir + "/bad.json";
  std::ofstream(path) << text;
  try {
    ReadCameraSet(path);
    FAIL() << "expected InputError for: " << text;
  } catch (const InputError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  }
}

TEST(CameraIo, BadFilesNameTheFileAndTheProblem) {
  const std::string good_camera =
      R"("fx_px": 1000, "fy_px": 1000, "cx_px": 960, "cy_px": 540, "width_px": 1920, "height_px": 1080, "translation_m": [0, 0, 4])";
  ExpectCameraFileError("{not json", "malformed JSON");
  ExpectCameraFileError(R"({"format": "other", "version": 1, "cameras": []})",
                        "format");
  ExpectCameraFileError(
      R"({"format": "mimic2d.cameras", "version": 1, "cameras": []})",
      "no cameras");
  ExpectCameraFileError(
      R"({"format": "mimic2d.cameras", "version": 1, "cameras": [{"name": "a", )" +
          good_camera +
          R"(, "rotation_world_to_camera": [[1, 0, 0], [0, 1, 0]]}]})",
      "expected 3 elements");
  ExpectCameraFileError(
      R"({"format": "mimic2d.cameras", "version": 1, "cameras": [{"name": "a", )" +
          good_camera +
          R"(, "rotation_world_to_camera": [[2, 0, 0], [0, 1, 0], [0, 0, 1]]}]})",
      "not a rotation");
  ExpectCameraFileError(
      R"({"format": "mimic2d.cameras", "version": 1, "cameras": [{"name": "a", "fx_px": null, "fy_px": 1, "cx_px": 1, "cy_px": 1, "width_px": 2, "height_px": 2}]})",
      "fx_px");
}

}  // namespace
}  // namespace m2d
