// media: images and video in and out — RGB images, PNG, video decoding and
// MP4 encoding through the ffmpeg binary, child processes; shared by
// rendering and detection.
#ifndef MIMIC2D_MEDIA_CAIRO_BRIDGE_H_
#define MIMIC2D_MEDIA_CAIRO_BRIDGE_H_

#include <cairo.h>

#include <memory>

#include "media/image.h"

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

#endif  // MIMIC2D_MEDIA_CAIRO_BRIDGE_H_
