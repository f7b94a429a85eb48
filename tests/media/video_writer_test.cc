#include "media/video_writer.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"
#include "common/file_io.h"
#include "media/media_test_util.h"

namespace m2d {
namespace {

Rgb FrameColor(int frame) {
  return {static_cast<uint8_t>(20 * frame), 100,
          static_cast<uint8_t>(250 - 20 * frame)};
}

TEST(Mp4Writer, WritesEveryFrameAtItsSize) {
  const std::string path = testing::TempDir("mp4") + "/out/clip.mp4";
  Mp4Options options;
  options.fps = 24.0;
  Mp4Writer writer(path, 320, 240, options);
  for (int frame = 0; frame < 12; ++frame) {
    writer.Write(RgbImage(320, 240, FrameColor(frame)));
  }
  EXPECT_FALSE(std::filesystem::exists(path));  // appears at Finish()
  writer.Finish();
  EXPECT_EQ(writer.frames_written(), 12);

  const testing::VideoInfo info = testing::ProbeVideo(path);
  EXPECT_EQ(info.frames, 12);
  EXPECT_EQ(info.width_px, 320);
  EXPECT_EQ(info.height_px, 240);
  EXPECT_EQ(info.codec, "h264");
  EXPECT_EQ(info.pixel_format, "yuv420p");

  // Frame 5 decodes to its colour (up to compression).
  const std::string raw = path + ".frame5.rgb";
  ProcessResult decode = RunProcess(
      {"ffmpeg", "-v", "error", "-y", "-i", path, "-vf", "select=eq(n\\,5)",
       "-frames:v", "1", "-f", "rawvideo", "-pix_fmt", "rgb24", raw});
  ASSERT_TRUE(decode.ok()) << decode.output;
  const std::string pixels = ReadFileText(raw);
  ASSERT_EQ(pixels.size(), 320u * 240u * 3u);
  const Rgb expected = FrameColor(5);
  const size_t center = (120 * 320 + 160) * 3;
  const Rgb decoded = {static_cast<uint8_t>(pixels[center]),
                       static_cast<uint8_t>(pixels[center + 1]),
                       static_cast<uint8_t>(pixels[center + 2])};
  EXPECT_LE(testing::ColorDistance(decoded, expected), 6);
}

TEST(Mp4Writer, RejectsOddSizesAndWrongFrames) {
  const std::string folder = testing::TempDir("mp4_bad");
  EXPECT_THROW(Mp4Writer(folder + "/a.mp4", 321, 240, Mp4Options()),
               ConfigError);
  Mp4Writer writer(folder + "/b.mp4", 64, 48, Mp4Options());
  EXPECT_THROW(writer.Write(RgbImage(32, 48)), std::invalid_argument);
}

TEST(Mp4Writer, AbandonedVideoLeavesNoFile) {
  const std::string folder = testing::TempDir("mp4_abandon");
  {
    Mp4Writer writer(folder + "/c.mp4", 64, 48, Mp4Options());
    writer.Write(RgbImage(64, 48));
  }
  EXPECT_TRUE(std::filesystem::is_empty(folder));
}

TEST(Mp4Writer, MissingFfmpegIsAClearError) {
  Mp4Options options;
  options.ffmpeg_binary = "/nonexistent/ffmpeg";
  try {
    Mp4Writer writer(testing::TempDir("mp4_missing") + "/d.mp4", 64, 48,
                     options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/ffmpeg"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace m2d
