// `mimic2d bench train`'s measurement (rl/train_benchmark.h) on a tiny
// config: every setting gets a row with its ratios, after the bound.
#include "rl/train_benchmark.h"

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/file_io.h"
#include "rl/tiny_walk_config.h"

namespace m2d {
namespace {

TEST(TrainBenchmark, PrintsTheBoundAndARowPerSetting) {
  const std::string walk_path =
      testing::SourcePath("assets/motions/deepmimic/humanoid3d_walk.txt");
  const std::string dir = testing::TempDir("train_benchmark");
  TrainConfig config = testing::TinyWalkConfig(walk_path, dir);
  config.ppo.num_envs = 4;
  config.ppo.steps_per_env = 8;
  config.ppo.minibatch_size = 16;
  config.Validate();
  TrainBenchmarkOptions options;
  options.config_path = dir + "/config.yaml";
  WriteFileAtomic(options.config_path, TrainConfigToYaml(config));
  options.iterations = 2;
  options.warmup_iterations = 1;
  options.torch_threads = {1};
  options.precisions = {TrainingPrecision::kFp32, TrainingPrecision::kBf16};
  options.bound_steps = 10;

  ::testing::internal::CaptureStdout();
  RunTrainBenchmark(options);
  const std::string out = ::testing::internal::GetCapturedStdout();
  std::printf("%s", out.c_str());
  EXPECT_NE(out.find("simulation-only bound: "), std::string::npos);
  EXPECT_NE(out.find("of bound"), std::string::npos);
  EXPECT_NE(out.find("\n1 fp32 "), std::string::npos);
  EXPECT_NE(out.find("\n1 bf16 "), std::string::npos);
  // The overlapped row runs at the last precision listed.
  EXPECT_NE(out.find("\noverlap 1+1 bf16 "), std::string::npos);

  options.torch_threads.clear();
  options.overlap = false;
  EXPECT_THROW(RunTrainBenchmark(options), ConfigError);
}

}  // namespace
}  // namespace m2d
