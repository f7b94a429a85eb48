// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_GL_CAMERA_H_
#define MIMIC2D_RENDER_GL_CAMERA_H_

#include <mujoco/mujoco.h>

#include "camera/pinhole.h"

namespace m2d {

// MuJoCo 2.2.2 derives the frustum's half width from the viewport's aspect
// ratio, so it draws only square pixels: fx and fy may differ by this
// fraction at most (a rounding of the image size, not a real aspect).
inline constexpr double kMaxPixelAspectError = 1e-3;

// The OpenGL camera that draws exactly what `camera` sees into a viewport
// of its image size: the same centre and axes (OpenCV x right, y down, z
// forward -> GL up = -y), and a frustum whose edges are the image edges at
// `near_m` (principal point offsets become an off-centre frustum:
// frustum_center horizontally, asymmetric bottom/top vertically).
// Image coordinates follow pinhole.h: pixel (i, j) covers [i, i+1) x
// [j, j+1), as GL's window coordinates do. Throws ConfigError for
// non-square pixels or a bad near/far range.
mjvGLCamera GlCameraFromPinhole(const PinholeCamera& camera, double near_m,
                                double far_m);

// `camera` for an image scaled by `scale` (pixels u -> scale * u). The
// image size becomes the smallest even size covering the scaled image
// (H.264 in yuv420p needs even sizes), so the frame may gain a pixel of
// extra view on the right or bottom but is never stretched.
PinholeCamera ScaleCamera(const PinholeCamera& camera, double scale);

// A window of `camera`'s image magnified to the whole image: the window's
// top-left corner at (x0_px, y0_px), its size the image's / `zoom`. The
// same camera centre and orientation (a digital zoom that loses no
// resolution, since the scene is drawn again); pixel p of `camera` lands
// at (p - (x0, y0)) x zoom.
PinholeCamera CropCamera(const PinholeCamera& camera, double x0_px,
                         double y0_px, double zoom);

// A camera orbiting a point, placed like MuJoCo's free camera: it looks
// along (cos el cos az, cos el sin az, sin el) from `distance_m` away.
struct OrbitCameraOptions {
  double azimuth_deg = 90.0;     // 90: looking along +y (the humanoid's left
                                 // side faces away; we see its right)
  double elevation_deg = -15.0;  // negative: looking down
  double distance_m = 4.0;       // from the point looked at
  double fovy_deg = 45.0;        // vertical field of view
  void Validate() const;         // throws ConfigError
};

// The orbit camera looking at `target_m` with a `width_px` x `height_px`
// image (square pixels, principal point at the centre).
PinholeCamera OrbitCamera(const OrbitCameraOptions& options,
                          const Eigen::Vector3d& target_m, int width_px,
                          int height_px);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_GL_CAMERA_H_
