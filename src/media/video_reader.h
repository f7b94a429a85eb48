// media: images and video in and out — RGB images, PNG, video decoding and
// MP4 encoding through the ffmpeg binary, child processes; shared by
// rendering and detection.
#ifndef MIMIC2D_MEDIA_VIDEO_READER_H_
#define MIMIC2D_MEDIA_VIDEO_READER_H_

#include <cstdint>
#include <memory>
#include <string>

#include "media/image.h"
#include "media/subprocess.h"

namespace m2d {

// The first video stream of a file (a still image is a one-frame video).
struct VideoStreamInfo {
  int width_px = 0;
  int height_px = 0;
  double fps = 0.0;         // average frame rate (Hz)
  int64_t num_frames = -1;  // as the container says; -1 when it does not
  std::string codec;
};

// Asks ffprobe. InputError naming the file when it is missing, is not a
// video or image ffmpeg reads, or has no video stream.
VideoStreamInfo ProbeVideoStream(const std::string& path);

// Decodes a video's frames in order, as packed RGB, through an ffmpeg child
// process (one frame in memory at a time).
class VideoReader {
 public:
  explicit VideoReader(const std::string& path);
  ~VideoReader();
  VideoReader(const VideoReader&) = delete;
  VideoReader& operator=(const VideoReader&) = delete;

  const VideoStreamInfo& info() const { return info_; }
  // The next frame into `frame` (resized to the stream's size); false at
  // the end. At the end, InputError naming the file when ffmpeg failed or
  // reported damaged data before the container's frame count was reached
  // (a truncated or corrupt file), with ffmpeg's message.
  bool Read(RgbImage* frame);
  int64_t frames_read() const { return frames_read_; }

 private:
  std::string path_;
  VideoStreamInfo info_;
  std::unique_ptr<PipedProcess> ffmpeg_;
  int64_t frames_read_ = 0;
};

// The first frame of an image or video file.
RgbImage ReadImageFile(const std::string& path);

}  // namespace m2d

#endif  // MIMIC2D_MEDIA_VIDEO_READER_H_
