#include "media/video_reader.h"

#include <filesystem>
#include <sstream>

#include "common/error.h"

namespace m2d {
namespace {

// "30000/1001" or "25/1" or "0/0".
double ParseRate(const std::string& text) {
  const size_t slash = text.find('/');
  try {
    if (slash == std::string::npos) return std::stod(text);
    const double numerator = std::stod(text.substr(0, slash));
    const double denominator = std::stod(text.substr(slash + 1));
    return denominator > 0 ? numerator / denominator : 0.0;
  } catch (const std::exception&) {
    return 0.0;
  }
}

// The first line of a child's output, for an error message.
std::string FirstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "(no message)" : line;
}

}  // namespace

VideoStreamInfo ProbeVideoStream(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(path, "no such file");
  ProcessResult result = RunProcess(
      {"ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
       "stream=width,height,avg_frame_rate,r_frame_rate,nb_frames,codec_name",
       "-of", "default=noprint_wrappers=1", path});
  if (!result.ok()) {
    throw InputError(path, "not a video or image ffmpeg can read: " +
                               FirstLine(result.output));
  }
  VideoStreamInfo info;
  double average_rate = 0, base_rate = 0;
  std::istringstream lines(result.output);
  std::string line;
  while (std::getline(lines, line)) {
    const size_t equals = line.find('=');
    if (equals == std::string::npos) continue;
    const std::string key = line.substr(0, equals);
    const std::string value = line.substr(equals + 1);
    try {
      if (key == "width") info.width_px = std::stoi(value);
      if (key == "height") info.height_px = std::stoi(value);
      if (key == "nb_frames" && value != "N/A")
        info.num_frames = std::stoll(value);
    } catch (const std::exception&) {
    }
    if (key == "codec_name") info.codec = value;
    if (key == "avg_frame_rate") average_rate = ParseRate(value);
    if (key == "r_frame_rate") base_rate = ParseRate(value);
  }
  if (info.width_px <= 0 || info.height_px <= 0)
    throw InputError(path, "has no video stream (not a video or image)");
  info.fps = average_rate > 0 ? average_rate : base_rate;
  return info;
}

VideoReader::VideoReader(const std::string& path)
    : path_(path), info_(ProbeVideoStream(path)) {
  ffmpeg_ = std::make_unique<PipedProcess>(
      std::vector<std::string>{"ffmpeg", "-v", "error", "-nostdin", "-i", path,
                               "-map", "0:v:0", "-f", "rawvideo", "-pix_fmt",
                               "rgb24", "-"},
      PipeDirection::kFromChild);
}

VideoReader::~VideoReader() = default;

bool VideoReader::Read(RgbImage* frame) {
  if (!ffmpeg_) return false;
  if (frame->width_px() != info_.width_px ||
      frame->height_px() != info_.height_px) {
    *frame = RgbImage(info_.width_px, info_.height_px);
  }
  const size_t got = ffmpeg_->Read(frame->data(), frame->size_bytes());
  if (got == frame->size_bytes()) {
    ++frames_read_;
    return true;
  }
  // The end: ffmpeg must have finished cleanly, with every frame.
  ProcessResult result = ffmpeg_->Wait();
  ffmpeg_.reset();
  if (!result.ok()) {
    throw InputError(path_, "decoding failed after " +
                                std::to_string(frames_read_) +
                                " frames: " + FirstLine(result.output));
  }
  if (got != 0) {
    throw InputError(path_, "the video ends inside frame " +
                                std::to_string(frames_read_ + 1) +
                                " (truncated)");
  }
  if (!result.output.empty() && info_.num_frames > 0 &&
      frames_read_ < info_.num_frames) {
    throw InputError(path_, "damaged: decoded " + std::to_string(frames_read_) +
                                " of " + std::to_string(info_.num_frames) +
                                " frames; ffmpeg: " + FirstLine(result.output));
  }
  return false;
}

RgbImage ReadImageFile(const std::string& path) {
  VideoReader reader(path);
  RgbImage image;
  if (!reader.Read(&image)) throw InputError(path, "has no frame");
  return image;
}

}  // namespace m2d
