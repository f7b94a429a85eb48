#include "media/image.h"

#include <cstring>
#include <stdexcept>

#include "common/error.h"
#include "common/file_io.h"
#include "media/cairo_bridge.h"

namespace m2d {
namespace {

// Cairo's 32-bit pixels are native-endian 0xAARRGGBB / 0x00RRGGBB.
inline uint32_t PackPixel(const uint8_t* rgb) {
  return 0xff000000u | (uint32_t{rgb[0]} << 16) | (uint32_t{rgb[1]} << 8) |
         uint32_t{rgb[2]};
}

cairo_status_t AppendToString(void* closure, const unsigned char* data,
                              unsigned int length) {
  static_cast<std::string*>(closure)->append(
      reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

RgbImage::RgbImage(int width_px, int height_px, Rgb fill)
    : width_px_(width_px), height_px_(height_px) {
  if (width_px <= 0 || height_px <= 0) {
    throw ConfigError("image size must be positive, got " +
                      std::to_string(width_px) + "x" +
                      std::to_string(height_px));
  }
  pixels_.resize(static_cast<size_t>(width_px) * height_px * 3);
  for (size_t i = 0; i < pixels_.size(); i += 3) {
    pixels_[i] = fill.r;
    pixels_[i + 1] = fill.g;
    pixels_[i + 2] = fill.b;
  }
}

Rgb RgbImage::at(int x, int y) const {
  const uint8_t* p =
      pixels_.data() + (static_cast<size_t>(y) * width_px_ + x) * 3;
  return {p[0], p[1], p[2]};
}

void RgbImage::set(int x, int y, Rgb color) {
  uint8_t* p = pixels_.data() + (static_cast<size_t>(y) * width_px_ + x) * 3;
  p[0] = color.r;
  p[1] = color.g;
  p[2] = color.b;
}

void RgbImage::Paste(const RgbImage& source, int x, int y) {
  if (x < 0 || y < 0 || x + source.width_px() > width_px_ ||
      y + source.height_px() > height_px_) {
    throw std::logic_error("RgbImage::Paste: source does not fit");
  }
  const size_t row_bytes = static_cast<size_t>(source.width_px()) * 3;
  for (int row = 0; row < source.height_px(); ++row) {
    std::memcpy(
        pixels_.data() + (static_cast<size_t>(y + row) * width_px_ + x) * 3,
        source.data() + row * row_bytes, row_bytes);
  }
}

CairoSurfacePtr SurfaceFromImage(const RgbImage& image) {
  CairoSurfacePtr surface(cairo_image_surface_create(
      CAIRO_FORMAT_RGB24, image.width_px(), image.height_px()));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error("cairo cannot allocate a " +
                             std::to_string(image.width_px()) + "x" +
                             std::to_string(image.height_px()) + " surface");
  }
  cairo_surface_flush(surface.get());
  unsigned char* base = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  for (int y = 0; y < image.height_px(); ++y) {
    auto* row =
        reinterpret_cast<uint32_t*>(base + static_cast<size_t>(y) * stride);
    const uint8_t* source =
        image.data() + static_cast<size_t>(y) * image.width_px() * 3;
    for (int x = 0; x < image.width_px(); ++x)
      row[x] = PackPixel(source + 3 * x);
  }
  cairo_surface_mark_dirty(surface.get());
  return surface;
}

void ImageFromSurface(cairo_surface_t* surface, RgbImage* image) {
  cairo_surface_flush(surface);
  const int width = cairo_image_surface_get_width(surface);
  const int height = cairo_image_surface_get_height(surface);
  if (image->width_px() != width || image->height_px() != height) {
    *image = RgbImage(width, height);
  }
  const unsigned char* base = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  const bool has_alpha =
      cairo_image_surface_get_format(surface) == CAIRO_FORMAT_ARGB32;
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const uint32_t*>(
        base + static_cast<size_t>(y) * stride);
    uint8_t* out = image->data() + static_cast<size_t>(y) * width * 3;
    for (int x = 0; x < width; ++x) {
      uint32_t pixel = row[x];
      uint32_t r = (pixel >> 16) & 0xff, g = (pixel >> 8) & 0xff,
               b = pixel & 0xff;
      if (has_alpha) {
        // Premultiplied alpha over white, so transparent PNG areas read as
        // white rather than black.
        const uint32_t a = pixel >> 24;
        r += 255 - a;
        g += 255 - a;
        b += 255 - a;
      }
      out[3 * x] = static_cast<uint8_t>(r);
      out[3 * x + 1] = static_cast<uint8_t>(g);
      out[3 * x + 2] = static_cast<uint8_t>(b);
    }
  }
}

RgbImage CropAndScale(const RgbImage& source, double x0_px, double y0_px,
                      double scale, int width_px, int height_px) {
  if (!(scale > 0) || width_px <= 0 || height_px <= 0 || source.empty()) {
    throw std::invalid_argument(
        "CropAndScale: needs a source, scale > 0 and "
        "a positive output size");
  }
  CairoSurfacePtr from = SurfaceFromImage(source);
  CairoSurfacePtr to(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width_px, height_px));
  CairoPtr cairo(cairo_create(to.get()));
  cairo_set_source_rgb(cairo.get(), 0.0, 0.0, 0.0);
  cairo_paint(cairo.get());
  cairo_scale(cairo.get(), scale, scale);
  cairo_translate(cairo.get(), -x0_px, -y0_px);
  cairo_set_source_surface(cairo.get(), from.get(), 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cairo.get()),
                           CAIRO_FILTER_BILINEAR);
  cairo_paint(cairo.get());
  RgbImage result;
  ImageFromSurface(to.get(), &result);
  return result;
}

std::string EncodePng(const RgbImage& image) {
  CairoSurfacePtr surface = SurfaceFromImage(image);
  std::string bytes;
  if (cairo_surface_write_to_png_stream(surface.get(), AppendToString,
                                        &bytes) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error("cairo cannot encode a PNG");
  }
  return bytes;
}

void WritePng(const std::string& path, const RgbImage& image) {
  WriteFileAtomic(path, EncodePng(image));
}

RgbImage ReadPng(const std::string& path) {
  CairoSurfacePtr surface(cairo_image_surface_create_from_png(path.c_str()));
  const cairo_status_t status = cairo_surface_status(surface.get());
  if (status != CAIRO_STATUS_SUCCESS) {
    throw InputError(path, std::string("cannot read as PNG: ") +
                               cairo_status_to_string(status));
  }
  RgbImage image;
  ImageFromSurface(surface.get(), &image);
  return image;
}

}  // namespace m2d
