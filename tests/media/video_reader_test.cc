#include "media/video_reader.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/file_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

const std::string kMedia = "/usr/share/doc/opencv-doc/examples/data/";

// Debian opencv-doc's pedestrian video: 768x576 at 10 fps, every frame.
TEST(VideoReader, DecodesEveryFrameOfARealVideo) {
  VideoReader reader(kMedia + "vtest.avi");
  EXPECT_EQ(reader.info().width_px, 768);
  EXPECT_EQ(reader.info().height_px, 576);
  EXPECT_NEAR(reader.info().fps, 10.0, 1e-9);
  RgbImage frame;
  int64_t frames = 0;
  long brightness = 0;
  while (reader.Read(&frame)) {
    ++frames;
    if (frames == 1) {
      for (size_t i = 0; i < frame.size_bytes(); i += 97)
        brightness += frame.data()[i];
    }
  }
  EXPECT_EQ(frames, 795);
  EXPECT_EQ(reader.frames_read(), 795);
  if (reader.info().num_frames > 0) {
    EXPECT_EQ(frames, reader.info().num_frames);
  }
  EXPECT_GT(brightness, 0);  // not a black frame
  EXPECT_FALSE(reader.Read(&frame));
}

TEST(VideoReader, AnImageIsOneFrame) {
  RgbImage image = ReadImageFile(kMedia + "messi5.jpg");
  EXPECT_EQ(image.width_px(), 548);
  EXPECT_EQ(image.height_px(), 342);
}

// Not a video, a missing file, a truncated video: errors naming the file.
TEST(VideoReader, BadFilesAreNamed) {
  const std::string dir = testing::TempDir("video_reader_bad");
  { std::ofstream(dir + "/notes.avi") << "this is not a video\n"; }
  try {
    VideoReader reader(dir + "/notes.avi");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), dir + "/notes.avi");
  }
  EXPECT_THROW(VideoReader(dir + "/missing.avi"), InputError);

  const std::string video = ReadFileText(kMedia + "vtest.avi");
  {
    std::ofstream(dir + "/cut.avi", std::ios::binary)
        << video.substr(0, video.size() / 3);
  }
  try {
    VideoReader reader(dir + "/cut.avi");
    RgbImage frame;
    int64_t frames = 0;
    while (reader.Read(&frame)) ++frames;
    FAIL() << "a third of the video read as whole (" << frames << " frames)";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), dir + "/cut.avi");
    std::printf("truncated video: %s\n", error.problem().c_str());
  }
}

}  // namespace
}  // namespace m2d
