#include "render/overlay.h"

#include <algorithm>
#include <cmath>

namespace m2d {
namespace {

void SetColor(cairo_t* cairo, Rgb color, double alpha = 1.0) {
  cairo_set_source_rgba(cairo, color.r / 255.0, color.g / 255.0,
                        color.b / 255.0, alpha);
}

}  // namespace

OverlaySizes OverlaySizesForHeight(int image_height_px) {
  // At 1080 px: 4 px lines, 6 px dots, 30 px text; never below legible
  // sizes on small frames.
  const double scale = image_height_px / 1080.0;
  OverlaySizes sizes;
  sizes.line_width_px = std::max(2.0, 4.0 * scale);
  sizes.dot_radius_px = std::max(2.5, 6.0 * scale);
  sizes.font_size_px = std::max(11.0, 30.0 * scale);
  return sizes;
}

OverlayCanvas::OverlayCanvas(RgbImage* image)
    : image_(image),
      surface_(SurfaceFromImage(*image)),
      cairo_(cairo_create(surface_.get())) {
  cairo_set_line_cap(cairo_.get(), CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cairo_.get(), CAIRO_LINE_JOIN_ROUND);
}

void OverlayCanvas::DrawSkeleton(const KeypointLayout& layout,
                                 const std::vector<Keypoint2D>& keypoints,
                                 Rgb color, const OverlaySizes& sizes) {
  cairo_t* cairo = cairo_.get();
  const int count =
      std::min<int>(layout.num_keypoints(), static_cast<int>(keypoints.size()));
  SetColor(cairo, color);
  cairo_set_line_width(cairo, sizes.line_width_px);
  for (const auto& [a, b] : layout.bones) {
    if (a >= count || b >= count) continue;
    if (!keypoints[a].IsPresent() || !keypoints[b].IsPresent()) continue;
    cairo_move_to(cairo, keypoints[a].x_px, keypoints[a].y_px);
    cairo_line_to(cairo, keypoints[b].x_px, keypoints[b].y_px);
  }
  cairo_stroke(cairo);
  for (int j = 0; j < count; ++j) {
    if (!keypoints[j].IsPresent()) continue;
    cairo_new_sub_path(cairo);
    cairo_arc(cairo, keypoints[j].x_px, keypoints[j].y_px, sizes.dot_radius_px,
              0.0, 2.0 * M_PI);
  }
  cairo_fill(cairo);
}

void OverlayCanvas::DrawRing(const Keypoint2D& point, double radius_px,
                             Rgb color, const OverlaySizes& sizes) {
  if (!point.IsPresent()) return;
  cairo_t* cairo = cairo_.get();
  SetColor(cairo, color);
  cairo_set_line_width(cairo, sizes.line_width_px);
  cairo_new_sub_path(cairo);
  cairo_arc(cairo, point.x_px, point.y_px, radius_px, 0.0, 2.0 * M_PI);
  cairo_stroke(cairo);
}

void OverlayCanvas::DrawLabel(const std::vector<LabelLine>& lines, double x_px,
                              double y_px, const OverlaySizes& sizes) {
  if (lines.empty()) return;
  cairo_t* cairo = cairo_.get();
  cairo_select_font_face(cairo, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cairo, sizes.font_size_px);
  cairo_font_extents_t font;
  cairo_font_extents(cairo, &font);
  const double padding = 0.4 * sizes.font_size_px;
  const double swatch_width = 1.6 * sizes.font_size_px;
  double text_width = 0.0;
  for (const LabelLine& line : lines) {
    cairo_text_extents_t extents;
    cairo_text_extents(cairo, line.text.c_str(), &extents);
    const double width =
        extents.x_advance + (line.swatch ? swatch_width + padding : 0.0);
    text_width = std::max(text_width, width);
  }
  const double line_height = font.height;
  cairo_rectangle(cairo, x_px, y_px, text_width + 2 * padding,
                  lines.size() * line_height + 2 * padding);
  cairo_set_source_rgba(cairo, 0.0, 0.0, 0.0, 0.55);
  cairo_fill(cairo);
  double baseline = y_px + padding + font.ascent;
  for (const LabelLine& line : lines) {
    double x = x_px + padding;
    if (line.swatch) {
      SetColor(cairo, line.color);
      cairo_set_line_width(cairo, std::max(2.0, 0.2 * sizes.font_size_px));
      const double mid = baseline - 0.35 * sizes.font_size_px;
      cairo_move_to(cairo, x, mid);
      cairo_line_to(cairo, x + swatch_width, mid);
      cairo_stroke(cairo);
      x += swatch_width + padding;
      cairo_set_source_rgb(cairo, 1.0, 1.0, 1.0);
    } else {
      SetColor(cairo, line.color);
    }
    cairo_move_to(cairo, x, baseline);
    cairo_show_text(cairo, line.text.c_str());
    baseline += line_height;
  }
}

void OverlayCanvas::Finish() { ImageFromSurface(surface_.get(), image_); }

}  // namespace m2d
