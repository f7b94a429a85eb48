// media: images and video in and out — RGB images, PNG, video decoding and
// MP4 encoding through the ffmpeg binary, child processes; shared by
// rendering and detection.
#ifndef MIMIC2D_MEDIA_IMAGE_H_
#define MIMIC2D_MEDIA_IMAGE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace m2d {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& other) const {
    return r == other.r && g == other.g && b == other.b;
  }
  bool operator!=(const Rgb& other) const { return !(*this == other); }
};

// A packed 8-bit RGB image, rows top to bottom (the layout ffmpeg's rgb24
// expects). Pixel (x, y) covers [x, x+1) × [y, y+1) in image coordinates.
class RgbImage {
 public:
  RgbImage() = default;
  RgbImage(int width_px, int height_px, Rgb fill = {});

  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  bool empty() const { return pixels_.empty(); }
  uint8_t* data() { return pixels_.data(); }
  const uint8_t* data() const { return pixels_.data(); }
  size_t size_bytes() const { return pixels_.size(); }

  Rgb at(int x, int y) const;
  void set(int x, int y, Rgb color);

  // Copies `source` with its top-left corner at (x, y); must fit.
  void Paste(const RgbImage& source, int x, int y);

 private:
  int width_px_ = 0;
  int height_px_ = 0;
  std::vector<uint8_t> pixels_;
};

// A window of `source` magnified `scale` times into a width_px x height_px
// image (bilinear, via cairo): output pixel (u, v) shows the source at
// (x0_px + u / scale, y0_px + v / scale). Outside the source: black. E.g.
// the source video beside a render that zooms in on the subject.
RgbImage CropAndScale(const RgbImage& source, double x0_px, double y0_px,
                      double scale, int width_px, int height_px);

// PNG bytes of `image` (via cairo).
std::string EncodePng(const RgbImage& image);
// Writes `image` as a PNG, atomically.
void WritePng(const std::string& path, const RgbImage& image);
// Reads a PNG (any cairo-readable colour type) into RGB; InputError naming
// the file when it is missing or not a PNG.
RgbImage ReadPng(const std::string& path);

}  // namespace m2d

#endif  // MIMIC2D_MEDIA_IMAGE_H_
