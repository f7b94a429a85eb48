#include "detect/tfjs_graph.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/file_io.h"
#include "media/subprocess.h"
#include "test_paths.h"

namespace m2d {
namespace {

const std::string kMedia = "/usr/share/doc/opencv-doc/examples/data/";

std::string ModelPath(const std::string& name) {
  return testing::SourcePath("assets/models/movenet/" + name + ".json");
}

// The test pattern of make_movenet_reference.js: (x*7 + y*13 + c*29) % 256.
torch::Tensor Pattern(int width, int height) {
  torch::Tensor image = torch::empty({1, height, width, 3}, torch::kInt);
  int32_t* data = image.data_ptr<int32_t>();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        data[(y * width + x) * 3 + c] = (x * 7 + y * 13 + c * 29) % 256;
  return image;
}

// The first frame of a Debian opencv-doc image or video, scaled by ffmpeg
// exactly as for the reference.
torch::Tensor Scaled(const std::string& file, int width, int height) {
  const std::string raw = testing::TempDir("tfjs_media") + "/frame.rgb";
  ProcessResult result =
      RunProcess({"ffmpeg", "-loglevel", "error", "-y", "-i", kMedia + file,
                  "-frames:v", "1", "-vf",
                  "scale=" + std::to_string(width) + ":" +
                      std::to_string(height) + ":flags=bilinear",
                  "-f", "rawvideo", "-pix_fmt", "rgb24", raw});
  EXPECT_TRUE(result.ok()) << result.output;
  const std::string bytes = ReadFileText(raw);
  EXPECT_EQ(bytes.size(), static_cast<size_t>(width * height * 3));
  return torch::from_blob(const_cast<char*>(bytes.data()),
                          {1, height, width, 3}, torch::kUInt8)
      .to(torch::kInt);
}

// The interpreter reproduces TF.js (tfjs 4.22.0, cpu backend) on the three
// MoveNet models, for a synthetic pattern, a real photograph and a video
// frame: every output within 1e-4 (single pose: y, x and score of 17
// keypoints; multipose: 6 people x (17 keypoints, box, score)).
TEST(TfjsGraph, MoveNetMatchesTfjsReferenceOutputs) {
  const nlohmann::json reference = nlohmann::json::parse(ReadFileText(
      testing::SourcePath("tests/detect/data/movenet_reference.json")));
  int compared = 0;
  for (const nlohmann::json& c : reference["cases"]) {
    const std::string name = c["model"], input_name = c["input"];
    const int width = c["width"], height = c["height"];
    SCOPED_TRACE(name + " on " + input_name);
    TfjsGraphModel model = TfjsGraphModel::Load(ModelPath(name));
    torch::Tensor input = input_name == "pattern" ? Pattern(width, height)
                          : input_name == "messi5"
                              ? Scaled("messi5.jpg", width, height)
                              : Scaled("vtest.avi", width, height);
    torch::Tensor output = model.Run(input);
    ASSERT_EQ(output.sizes(), c["shape"].get<std::vector<int64_t>>());
    const std::vector<float> expected = c["output"];
    const float* got = output.data_ptr<float>();
    double worst = 0.0;
    for (size_t i = 0; i < expected.size(); ++i)
      worst = std::max(worst, std::abs(double(got[i]) - expected[i]));
    EXPECT_LT(worst, 1e-4);
    std::printf("%s on %s: worst difference %.2g\n", name.c_str(),
                input_name.c_str(), worst);
    ++compared;
  }
  EXPECT_EQ(compared, 7);
}

// Damaged model files are named with what is wrong.
TEST(TfjsGraph, BadModelFilesAreNamed) {
  const std::string dir = testing::TempDir("tfjs_bad");
  EXPECT_THROW(TfjsGraphModel::Load(dir + "/missing.json"), InputError);
  { std::ofstream(dir + "/garbage.json") << "{not json"; }
  EXPECT_THROW(TfjsGraphModel::Load(dir + "/garbage.json"), InputError);
  // The real graph with a truncated weight file.
  const std::string json = ReadFileText(ModelPath("movenet-lightning"));
  { std::ofstream(dir + "/movenet-lightning.json") << json; }
  const std::string weights = ReadFileText(
      testing::SourcePath("assets/models/movenet/movenet-lightning.bin"));
  {
    std::ofstream(dir + "/movenet-lightning.bin", std::ios::binary)
        << weights.substr(0, weights.size() / 2);
  }
  try {
    TfjsGraphModel::Load(dir + "/movenet-lightning.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(error.problem().find("truncated"), std::string::npos)
        << error.problem();
  }
  // Its weights missing.
  std::filesystem::remove(dir + "/movenet-lightning.bin");
  EXPECT_THROW(TfjsGraphModel::Load(dir + "/movenet-lightning.json"),
               InputError);
  // An op the interpreter does not know.
  std::string unknown = json;
  const std::string sigmoid = "\"op\":\"Sigmoid\"";
  const size_t at = unknown.find(sigmoid);
  ASSERT_NE(at, std::string::npos);
  unknown.replace(at, sigmoid.size(), "\"op\":\"Sinh\"");
  {
    std::ofstream(dir + "/unknown.json") << unknown;
    std::ofstream(dir + "/movenet-lightning.bin", std::ios::binary) << weights;
  }
  try {
    TfjsGraphModel::Load(dir + "/unknown.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(error.problem().find("'Sinh'"), std::string::npos)
        << error.problem();
  }
  // A wrong input shape.
  TfjsGraphModel model = TfjsGraphModel::Load(ModelPath("movenet-lightning"));
  EXPECT_EQ(model.input_shape(), (std::vector<int64_t>{1, 192, 192, 3}));
  EXPECT_THROW(model.Run(torch::zeros({1, 100, 192, 3}, torch::kInt)),
               InputError);
}

}  // namespace
}  // namespace m2d
