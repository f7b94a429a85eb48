// media: images and video in and out — RGB images, PNG, video decoding and
// MP4 encoding through the ffmpeg binary, child processes; shared by
// rendering and detection.
#ifndef MIMIC2D_MEDIA_VIDEO_WRITER_H_
#define MIMIC2D_MEDIA_VIDEO_WRITER_H_

#include <memory>
#include <string>

#include "media/image.h"
#include "media/subprocess.h"

namespace m2d {

struct Mp4Options {
  double fps = 30.0;
  int crf = 20;                     // x264 quality: 0 lossless .. 51 worst
  std::string preset = "veryfast";  // x264 speed/size trade-off
  std::string ffmpeg_binary = "ffmpeg";
  void Validate() const;  // throws ConfigError
};

// Writes an H.264 MP4 (yuv420p, playable in browsers) by piping raw RGB
// frames into the ffmpeg binary. The file appears atomically at Finish():
// ffmpeg writes a temporary file next to it that is then renamed.
class Mp4Writer {
 public:
  // Width and height must be even (yuv420p). Throws ConfigError on bad
  // settings and std::runtime_error when ffmpeg cannot be started.
  Mp4Writer(const std::string& path, int width_px, int height_px,
            const Mp4Options& options);
  // Abandons an unfinished video: stops ffmpeg, removes the temporary file.
  ~Mp4Writer();
  Mp4Writer(const Mp4Writer&) = delete;
  Mp4Writer& operator=(const Mp4Writer&) = delete;

  // Appends one frame of the writer's size.
  void Write(const RgbImage& frame);
  // Flushes, checks ffmpeg's exit status and moves the video into place.
  // Throws std::runtime_error with ffmpeg's message on failure.
  void Finish();

  int frames_written() const { return frames_written_; }
  const std::string& path() const { return path_; }

 private:
  // Stops ffmpeg and removes the temporary file.
  void Abandon();
  [[noreturn]] void FailWithFfmpegOutput(const std::string& what);

  std::string path_;
  std::string temporary_path_;
  int width_px_;
  int height_px_;
  int frames_written_ = 0;
  std::unique_ptr<PipedProcess> ffmpeg_;
};

}  // namespace m2d

#endif  // MIMIC2D_MEDIA_VIDEO_WRITER_H_
