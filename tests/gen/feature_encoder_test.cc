#include "gen/feature_encoder.h"

#include <gtest/gtest.h>

#include <memory>

#include "eval/metrics.h"
#include "gen/gen_test_data.h"

namespace m2d {
namespace {

GenDataset ClipDataset(const std::string& clip, int azimuths) {
  return testing::ClipDataset(clip, azimuths, {5, 25}, 6.0);
}

TEST(FeatureEncoder, FidSeparatesMotionsAndNotHalvesOfOne) {
  // The encoder learns on the kick (held apart); in its features two
  // halves of the walk's views must be far closer to each other than the
  // walk is to the run.
  torch::set_num_threads(1);
  const GenDataset walk = ClipDataset("walk", 8);
  const GenDataset run = ClipDataset("run", 8);
  const GenDataset kick = ClipDataset("kick", 8);
  const torch::Tensor mean = torch::tensor(walk.mean),
                      std = torch::tensor(walk.std);
  FeatureEncoderOptions options;
  options.window_frames = 32;
  options.features = 16;
  options.width = 64;
  options.steps = 300;
  auto windows = [&](const std::vector<GenSequence>& sequences) {
    return DatasetWindows(sequences, 37, 32, 8, mean, std);
  };
  double loss = 0;
  FeatureEncoder encoder =
      TrainFeatureEncoder(windows(kick.sequences), 37, options, 1, &loss);
  std::vector<GenSequence> half[2];
  for (size_t i = 0; i < walk.sequences.size(); ++i)
    half[i % 2].push_back(walk.sequences[i]);
  auto gaussian = [&](const std::vector<GenSequence>& sequences) {
    return FitFeatureGaussian(EncodeWindows(encoder, windows(sequences)));
  };
  const double floor = FrechetDistance(gaussian(half[0]), gaussian(half[1]));
  const double across =
      FrechetDistance(gaussian(walk.sequences), gaussian(run.sequences));
  std::printf("encoder loss %.4f; FID walk halves %.3f, walk vs run %.3f\n",
              loss, floor, across);
  EXPECT_LT(floor, 0.25 * across);
}

}  // namespace
}  // namespace m2d
