// render: what happened, shown — offscreen MuJoCo video from a reference
// camera with 2D keypoint overlays, training plots and HTML reports.
#ifndef MIMIC2D_RENDER_CAIRO_BRIDGE_H_
#define MIMIC2D_RENDER_CAIRO_BRIDGE_H_

#include <cairo.h>

#include <memory>

#include "render/image.h"

namespace m2d {

struct CairoSurfaceDeleter {
  void operator()(cairo_surface_t* surface) const {
    cairo_surface_destroy(surface);
  }
};
struct CairoDeleter {
  void operator()(cairo_t* cairo) const { cairo_destroy(cairo); }
};
using CairoSurfacePtr = std::unique_ptr<cairo_surface_t, CairoSurfaceDeleter>;
using CairoPtr = std::unique_ptr<cairo_t, CairoDeleter>;

// A cairo RGB24 surface holding a copy of `image`.
CairoSurfacePtr SurfaceFromImage(const RgbImage& image);
// Copies a cairo image surface (RGB24 or ARGB32, alpha dropped) into
// `image`, resized to match.
void ImageFromSurface(cairo_surface_t* surface, RgbImage* image);

}  // namespace m2d

#endif  // MIMIC2D_RENDER_CAIRO_BRIDGE_H_
