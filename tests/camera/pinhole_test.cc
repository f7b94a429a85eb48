#include "camera/pinhole.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "common/error.h"

namespace m2d {
namespace {

Intrinsics TestIntrinsics() {
  Intrinsics k;
  k.fx_px = 1000;
  k.fy_px = 900;
  k.cx_px = 960;
  k.cy_px = 540;
  return k;
}

TEST(PinholeCamera, ProjectsHandComputedPoints) {
  // Identity extrinsics: camera at the origin looking down +z.
  PinholeCamera camera(TestIntrinsics(), Eigen::Matrix3d::Identity(),
                       Eigen::Vector3d::Zero());
  Projection p = camera.Project({1.0, -0.5, 4.0});
  ASSERT_TRUE(p.in_front);
  EXPECT_DOUBLE_EQ(p.pixel_px.x(), 1000 * 1.0 / 4.0 + 960);  // 1210
  EXPECT_DOUBLE_EQ(p.pixel_px.y(), 900 * -0.5 / 4.0 + 540);  // 427.5
  EXPECT_DOUBLE_EQ(p.depth_m, 4.0);

  // The optical axis lands on the principal point.
  Projection centre = camera.Project({0, 0, 7});
  EXPECT_DOUBLE_EQ(centre.pixel_px.x(), 960);
  EXPECT_DOUBLE_EQ(centre.pixel_px.y(), 540);
}

TEST(PinholeCamera, LookAtFromTheFrontSeesUpAsUp) {
  // Camera 5 m along +x, looking back at the origin; world +z is image-up
  // (smaller v) and world +y is image-right when seen from +x.
  PinholeCamera camera =
      PinholeCamera::LookAt(TestIntrinsics(), {5, 0, 1}, {0, 0, 1});
  Projection centre = camera.Project({0, 0, 1});
  EXPECT_NEAR(centre.pixel_px.x(), 960, 1e-9);
  EXPECT_NEAR(centre.pixel_px.y(), 540, 1e-9);
  EXPECT_NEAR(centre.depth_m, 5.0, 1e-12);
  Projection head = camera.Project({0, 0, 2});
  EXPECT_NEAR(head.pixel_px.y(), 540 - 900 * 1.0 / 5.0, 1e-9);
  Projection left = camera.Project({0, 1, 1});
  EXPECT_NEAR(left.pixel_px.x(), 960 + 1000 * 1.0 / 5.0, 1e-9);
  EXPECT_TRUE(camera.CenterWorld().isApprox(Eigen::Vector3d(5, 0, 1), 1e-12));
}

TEST(PinholeCamera, PointsBehindAreFlaggedWithNanPixels) {
  PinholeCamera camera(TestIntrinsics(), Eigen::Matrix3d::Identity(),
                       Eigen::Vector3d::Zero());
  for (double z : {-3.0, 0.0, kMinProjectDepth_m / 2}) {
    Projection p = camera.Project({0.2, 0.1, z});
    EXPECT_FALSE(p.in_front) << "z=" << z;
    EXPECT_TRUE(std::isnan(p.pixel_px.x()));
    EXPECT_TRUE(camera.ProjectJacobian({0.2, 0.1, z}).isZero());
  }
}

TEST(PinholeCamera, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1.5, 1.5);
  PinholeCamera camera =
      PinholeCamera::LookAt(TestIntrinsics(), {3, -2, 1.6}, {0, 0, 0.9});
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Vector3d point(coord(rng), coord(rng), 0.9 + coord(rng));
    Eigen::Matrix<double, 2, 3> analytic = camera.ProjectJacobian(point);
    Eigen::Matrix<double, 2, 3> numeric;
    const double h = 1e-6;
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d plus = point, minus = point;
      plus[i] += h;
      minus[i] -= h;
      numeric.col(i) =
          (camera.Project(plus).pixel_px - camera.Project(minus).pixel_px) /
          (2 * h);
    }
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(),
              1e-4 * (1 + analytic.norm()))
        << "point " << point.transpose();
  }
}

TEST(PinholeCamera, TranslatedMovesTheCentreOnly) {
  PinholeCamera camera =
      PinholeCamera::LookAt(TestIntrinsics(), {4, 0, 1}, {0, 0, 1});
  Eigen::Vector3d offset(2.0, -1.0, 0.0);
  PinholeCamera moved = camera.Translated(offset);
  EXPECT_TRUE(
      moved.CenterWorld().isApprox(camera.CenterWorld() + offset, 1e-12));
  // A point moved with the camera projects to the same pixel.
  Eigen::Vector3d point(0.3, 0.2, 1.4);
  EXPECT_TRUE(moved.Project(point + offset)
                  .pixel_px.isApprox(camera.Project(point).pixel_px, 1e-12));
}

TEST(PinholeCamera, LookAtRejectsDegenerateViews) {
  EXPECT_THROW(PinholeCamera::LookAt(TestIntrinsics(), {0, 0, 1}, {0, 0, 1}),
               ConfigError);
  EXPECT_THROW(PinholeCamera::LookAt(TestIntrinsics(), {0, 0, 5}, {0, 0, 1}),
               ConfigError);
}

}  // namespace
}  // namespace m2d
