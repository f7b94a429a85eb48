// tests: helpers for the media tests (and render's) — image comparisons,
// PNG headers and ffprobe.
#ifndef MIMIC2D_TESTS_MEDIA_MEDIA_TEST_UTIL_H_
#define MIMIC2D_TESTS_MEDIA_MEDIA_TEST_UTIL_H_

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "media/image.h"
#include "media/subprocess.h"
#include "test_paths.h"

namespace m2d::testing {

// Largest per-channel difference between two pixels.
inline int ColorDistance(Rgb a, Rgb b) {
  return std::max(
      {std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
}

struct PngSize {
  int width_px = 0;
  int height_px = 0;
};

// Width and height from a PNG's IHDR chunk; zeros if not a PNG.
inline PngSize ReadPngSize(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  unsigned char header[24] = {};
  file.read(reinterpret_cast<char*>(header), sizeof(header));
  const unsigned char signature[8] = {0x89, 'P',  'N',  'G',
                                      '\r', '\n', 0x1a, '\n'};
  if (!file || !std::equal(signature, signature + 8, header)) return {};
  auto big_endian = [&](int at) {
    return (header[at] << 24) | (header[at + 1] << 16) | (header[at + 2] << 8) |
           header[at + 3];
  };
  return {big_endian(16), big_endian(20)};
}

struct VideoInfo {
  int frames = 0;
  int width_px = 0;
  int height_px = 0;
  std::string codec;
  std::string pixel_format;
};

// Decodes every frame of the first video stream with ffprobe.
inline VideoInfo ProbeVideo(const std::string& path) {
  ProcessResult result = RunProcess(
      {"ffprobe", "-v", "error", "-select_streams", "v:0", "-count_frames",
       "-show_entries", "stream=nb_read_frames,width,height,codec_name,pix_fmt",
       "-of", "default=noprint_wrappers=1", path});
  VideoInfo info;
  if (!result.ok()) return info;
  std::istringstream lines(result.output);
  std::string line;
  while (std::getline(lines, line)) {
    const size_t equals = line.find('=');
    if (equals == std::string::npos) continue;
    const std::string key = line.substr(0, equals);
    const std::string value = line.substr(equals + 1);
    if (key == "nb_read_frames") info.frames = std::stoi(value);
    if (key == "width") info.width_px = std::stoi(value);
    if (key == "height") info.height_px = std::stoi(value);
    if (key == "codec_name") info.codec = value;
    if (key == "pix_fmt") info.pixel_format = value;
  }
  return info;
}

}  // namespace m2d::testing

#endif  // MIMIC2D_TESTS_MEDIA_MEDIA_TEST_UTIL_H_
