#include "render/gl_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/error.h"

namespace m2d {
namespace {

PinholeCamera TestCamera(double cx_px, double cy_px) {
  Intrinsics k;
  k.fx_px = k.fy_px = 800.0;
  k.cx_px = cx_px;
  k.cy_px = cy_px;
  k.width_px = 1280;
  k.height_px = 720;
  return PinholeCamera::LookAt(k, {3.0, -1.0, 1.5}, {0.0, 0.5, 1.0});
}

// The GL camera's ray through a point (x, y) of the near plane (GL y up).
Eigen::Vector3d NearPlanePoint(const mjvGLCamera& gl, double x, double y) {
  Eigen::Vector3d pos(gl.pos[0], gl.pos[1], gl.pos[2]);
  Eigen::Vector3d forward(gl.forward[0], gl.forward[1], gl.forward[2]);
  Eigen::Vector3d up(gl.up[0], gl.up[1], gl.up[2]);
  Eigen::Vector3d right = forward.cross(up);
  return pos + gl.frustum_near * forward + x * right + y * up;
}

TEST(GlCameraFromPinhole, FrustumEdgesAreTheImageEdges) {
  const PinholeCamera camera = TestCamera(600.0, 400.0);
  const mjvGLCamera gl = GlCameraFromPinhole(camera, 0.05, 100.0);
  // MuJoCo 2.2.2: half width = aspect x (top - bottom) / 2, centred on
  // frustum_center.
  const double half_width =
      0.5 * 1280.0 / 720.0 * (gl.frustum_top - gl.frustum_bottom);
  const double left = gl.frustum_center - half_width;
  const double right = gl.frustum_center + half_width;
  struct Corner {
    double x, y, u, v;
  } corners[] = {{left, gl.frustum_top, 0, 0},
                 {right, gl.frustum_top, 1280, 0},
                 {left, gl.frustum_bottom, 0, 720},
                 {right, gl.frustum_bottom, 1280, 720}};
  for (const Corner& corner : corners) {
    const Projection p = camera.Project(NearPlanePoint(gl, corner.x, corner.y));
    ASSERT_TRUE(p.in_front);
    EXPECT_NEAR(p.pixel_px.x(), corner.u, 1e-3);
    EXPECT_NEAR(p.pixel_px.y(), corner.v, 1e-3);
  }
  // The camera sits at the pinhole's centre.
  const Eigen::Vector3d center = camera.CenterWorld();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(gl.pos[i], center[i], 1e-6);
}

TEST(GlCameraFromPinhole, CenteredPrincipalPointGivesASymmetricFrustum) {
  const mjvGLCamera gl =
      GlCameraFromPinhole(TestCamera(640.0, 360.0), 0.1, 10.0);
  EXPECT_NEAR(gl.frustum_center, 0.0, 1e-7);
  EXPECT_NEAR(gl.frustum_top, -gl.frustum_bottom, 1e-7);
  EXPECT_NEAR(gl.frustum_top, 0.1 * 360.0 / 800.0, 1e-7);
}

TEST(GlCameraFromPinhole, RejectsNonSquarePixelsAndBadClipRanges) {
  Intrinsics k;
  k.fx_px = 1000.0;
  k.fy_px = 1100.0;
  const PinholeCamera stretched =
      PinholeCamera::LookAt(k, {3.0, 0.0, 1.0}, {0.0, 0.0, 1.0});
  EXPECT_THROW(GlCameraFromPinhole(stretched, 0.1, 10.0), ConfigError);
  EXPECT_THROW(GlCameraFromPinhole(TestCamera(640, 360), 0.0, 10.0),
               ConfigError);
  EXPECT_THROW(GlCameraFromPinhole(TestCamera(640, 360), 1.0, 0.5),
               ConfigError);
}

TEST(ScaleCamera, ScalesPixelsAndRoundsTheSizeUpToEven) {
  const PinholeCamera camera = TestCamera(600.0, 400.0);
  const PinholeCamera third = ScaleCamera(camera, 1.0 / 3.0);
  // 1280/3 = 426.7 -> 428 (even, covers the image); 720/3 = 240.
  EXPECT_EQ(third.intrinsics().width_px, 428);
  EXPECT_EQ(third.intrinsics().height_px, 240);
  const Eigen::Vector3d point(0.2, 0.4, 1.3);
  EXPECT_TRUE(third.Project(point).pixel_px.isApprox(
      camera.Project(point).pixel_px / 3.0, 1e-12));
  Intrinsics odd = camera.intrinsics();
  odd.width_px = 1279;
  odd.height_px = 719;
  const PinholeCamera same =
      ScaleCamera(PinholeCamera(odd, camera.rotation_world_to_camera(),
                                camera.translation_m()),
                  1.0);
  EXPECT_EQ(same.intrinsics().width_px, 1280);
  EXPECT_EQ(same.intrinsics().height_px, 720);
  EXPECT_EQ(same.intrinsics().fx_px, odd.fx_px);
  EXPECT_THROW(ScaleCamera(camera, 0.0), ConfigError);
}

}  // namespace
}  // namespace m2d
