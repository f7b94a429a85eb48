#include "media/video_writer.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "common/error.h"

namespace m2d {
namespace {

std::string FormatRate(double fps) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", fps);
  return text;
}

}  // namespace

void Mp4Options::Validate() const {
  if (!(std::isfinite(fps) && fps > 0 && fps <= 1000)) {
    throw ConfigError("video frame rate must be in (0, 1000] fps");
  }
  if (crf < 0 || crf > 51) throw ConfigError("video crf must be in [0, 51]");
  if (preset.empty()) throw ConfigError("video preset must not be empty");
}

Mp4Writer::Mp4Writer(const std::string& path, int width_px, int height_px,
                     const Mp4Options& options)
    : path_(path), width_px_(width_px), height_px_(height_px) {
  options.Validate();
  if (width_px < 2 || height_px < 2 || width_px % 2 || height_px % 2) {
    throw ConfigError("MP4 (H.264, yuv420p) needs an even frame size, got " +
                      std::to_string(width_px) + "x" +
                      std::to_string(height_px));
  }
  std::filesystem::path target(path);
  if (target.has_parent_path()) {
    std::filesystem::create_directories(target.parent_path());
  }
  temporary_path_ = path + ".partial." + std::to_string(::getpid()) + ".tmp";
  const std::string size =
      std::to_string(width_px) + "x" + std::to_string(height_px);
  // -f mp4: the temporary name has no .mp4 suffix to guess from.
  // +faststart: the index goes first, so browsers play while loading.
  ffmpeg_ = std::make_unique<PipedProcess>(
      std::vector<std::string>{options.ffmpeg_binary,
                               "-hide_banner",
                               "-loglevel",
                               "error",
                               "-y",
                               "-f",
                               "rawvideo",
                               "-pix_fmt",
                               "rgb24",
                               "-video_size",
                               size,
                               "-framerate",
                               FormatRate(options.fps),
                               "-i",
                               "pipe:0",
                               "-an",
                               "-c:v",
                               "libx264",
                               "-preset",
                               options.preset,
                               "-crf",
                               std::to_string(options.crf),
                               "-pix_fmt",
                               "yuv420p",
                               "-movflags",
                               "+faststart",
                               "-f",
                               "mp4",
                               temporary_path_});
}

Mp4Writer::~Mp4Writer() {
  if (ffmpeg_ != nullptr) Abandon();
}

void Mp4Writer::Abandon() {
  ffmpeg_.reset();
  std::error_code ignored;
  std::filesystem::remove(temporary_path_, ignored);
}

void Mp4Writer::FailWithFfmpegOutput(const std::string& what) {
  ProcessResult result = ffmpeg_->Wait();
  Abandon();
  throw std::runtime_error(path_ + ": " + what + " (ffmpeg exit code " +
                           std::to_string(result.exit_code) +
                           "): " + result.output);
}

void Mp4Writer::Write(const RgbImage& frame) {
  if (ffmpeg_ == nullptr) throw std::logic_error("Mp4Writer: already finished");
  if (frame.width_px() != width_px_ || frame.height_px() != height_px_) {
    throw std::invalid_argument(
        "Mp4Writer: frame is " + std::to_string(frame.width_px()) + "x" +
        std::to_string(frame.height_px()) + ", the video " +
        std::to_string(width_px_) + "x" + std::to_string(height_px_));
  }
  if (!ffmpeg_->Write(frame.data(), frame.size_bytes())) {
    FailWithFfmpegOutput("ffmpeg stopped reading frames");
  }
  ++frames_written_;
}

void Mp4Writer::Finish() {
  if (ffmpeg_ == nullptr) throw std::logic_error("Mp4Writer: already finished");
  if (frames_written_ == 0) {
    Abandon();
    throw std::runtime_error(path_ + ": no frames to write");
  }
  ProcessResult result = ffmpeg_->Wait();
  if (!result.ok()) {
    Abandon();
    throw std::runtime_error(path_ + ": ffmpeg failed (exit code " +
                             std::to_string(result.exit_code) +
                             "): " + result.output);
  }
  ffmpeg_.reset();
  std::filesystem::rename(temporary_path_, path_);
}

}  // namespace m2d
