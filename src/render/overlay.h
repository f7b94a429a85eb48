// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_OVERLAY_H_
#define MIMIC2D_RENDER_OVERLAY_H_

#include <string>
#include <vector>

#include "media/cairo_bridge.h"
#include "media/image.h"
#include "motion/clip2d.h"
#include "motion/layout.h"

namespace m2d {

// Sizes of the drawn skeletons and labels, scaled with the image height so
// a frame looks the same at any resolution.
struct OverlaySizes {
  double line_width_px = 2.0;
  double dot_radius_px = 3.0;
  double font_size_px = 14.0;
};
OverlaySizes OverlaySizesForHeight(int image_height_px);

struct LabelLine {
  std::string text;
  Rgb color = {255, 255, 255};
  bool swatch = false;  // a short line of `color` before the text (legend)
};

// Antialiased drawing over an image (cairo). Draw calls accumulate on a
// copy; Finish() writes the result back into the image.
class OverlayCanvas {
 public:
  explicit OverlayCanvas(RgbImage* image);

  // The layout's bones between present keypoints and a dot on each present
  // keypoint, in image pixels (pixel (i, j) covers [i, i+1) x [j, j+1)).
  // `keypoints` has layout.num_keypoints() entries; missing ones (see
  // Keypoint2D::IsPresent) and their bones are skipped.
  void DrawSkeleton(const KeypointLayout& layout,
                    const std::vector<Keypoint2D>& keypoints, Rgb color,
                    const OverlaySizes& sizes);

  // A circle of `radius_px` around `point` (an object's centre, e.g. a
  // ball's), outlined with the skeleton's line width; nothing when the
  // point is missing.
  void DrawRing(const Keypoint2D& point, double radius_px, Rgb color,
                const OverlaySizes& sizes);

  // Lines of text on a translucent dark box with its top-left corner at
  // (x, y).
  void DrawLabel(const std::vector<LabelLine>& lines, double x_px, double y_px,
                 const OverlaySizes& sizes);

  void Finish();

 private:
  RgbImage* image_;
  CairoSurfacePtr surface_;
  CairoPtr cairo_;
};

}  // namespace m2d

#endif  // MIMIC2D_RENDER_OVERLAY_H_
