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

constexpr char kMessi[] = "/usr/share/doc/opencv-doc/examples/data/messi5.jpg";

std::string ModelPath(const std::string& name) {
  return testing::SourcePath("assets/models/movenet/" + name + ".json");
}

// The test pattern of make_movenet_reference.js: (x*7 + y*13 + c*29) % 256.
torch::Tensor Pattern(int size) {
  torch::Tensor image = torch::empty({1, size, size, 3}, torch::kInt);
  int32_t* data = image.data_ptr<int32_t>();
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 3; ++c)
        data[(y * size + x) * 3 + c] = (x * 7 + y * 13 + c * 29) % 256;
  return image;
}

// messi5.jpg scaled by ffmpeg exactly as for the reference.
torch::Tensor Messi(int size) {
  const std::string dir = testing::TempDir("tfjs_messi");
  const std::string raw = dir + "/messi.rgb";
  const std::string side = std::to_string(size);
  ProcessResult result =
      RunProcess({"ffmpeg", "-loglevel", "error", "-y", "-i", kMessi, "-vf",
                  "scale=" + side + ":" + side + ":flags=bilinear", "-f",
                  "rawvideo", "-pix_fmt", "rgb24", raw});
  EXPECT_TRUE(result.ok()) << result.output;
  const std::string bytes = ReadFileText(raw);
  EXPECT_EQ(bytes.size(), static_cast<size_t>(size * size * 3));
  torch::Tensor image = torch::from_blob(const_cast<char*>(bytes.data()),
                                         {1, size, size, 3}, torch::kUInt8)
                            .to(torch::kInt);
  return image;
}

// The interpreter reproduces TF.js (tfjs 4.22.0, cpu backend) on both
// single-pose models, for a synthetic pattern and a real photograph:
// y, x and score of all 17 keypoints within 1e-4.
TEST(TfjsGraph, MoveNetMatchesTfjsReferenceOutputs) {
  const nlohmann::json reference = nlohmann::json::parse(ReadFileText(
      testing::SourcePath("tests/detect/data/movenet_reference.json")));
  int compared = 0;
  for (const nlohmann::json& c : reference["cases"]) {
    const std::string name = c["model"];
    const int size = c["size"];
    SCOPED_TRACE(name + " on " + c["input"].get<std::string>());
    TfjsGraphModel model = TfjsGraphModel::Load(ModelPath(name));
    EXPECT_EQ(model.input_shape(), (std::vector<int64_t>{1, size, size, 3}));
    torch::Tensor input = c["input"] == "pattern" ? Pattern(size) : Messi(size);
    torch::Tensor output = model.Run(input);
    ASSERT_EQ(output.sizes(), (std::vector<int64_t>{1, 1, 17, 3}));
    const std::vector<float> expected = c["output"];
    const float* got = output.data_ptr<float>();
    double worst = 0.0;
    for (size_t i = 0; i < expected.size(); ++i)
      worst = std::max(worst, std::abs(double(got[i]) - expected[i]));
    EXPECT_LT(worst, 1e-4);
    std::printf("%s on %s: worst difference %.2g\n", name.c_str(),
                c["input"].get<std::string>().c_str(), worst);
    ++compared;
  }
  EXPECT_EQ(compared, 4);
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
  EXPECT_THROW(model.Run(torch::zeros({1, 100, 192, 3}, torch::kInt)),
               InputError);
}

}  // namespace
}  // namespace m2d
