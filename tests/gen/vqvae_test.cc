#include "gen/vqvae.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include "gen/motion_dataset.h"

namespace m2d {
namespace {

// A smooth synthetic X^can window set: local poses on slow sinusoids, a
// steady root step and a slowly breathing scale.
torch::Tensor SyntheticFeatures(int batch, int frames, int phase_seed) {
  torch::Tensor t =
      torch::arange(frames, torch::kFloat).unsqueeze(0).unsqueeze(2);
  torch::Tensor phase = torch::arange(batch, torch::kFloat)
                            .add(phase_seed)
                            .unsqueeze(1)
                            .unsqueeze(2);
  torch::Tensor channel =
      torch::arange(37, torch::kFloat).unsqueeze(0).unsqueeze(0);
  torch::Tensor x = 0.5 * torch::sin(0.2 * t + phase + 0.7 * channel);
  x.narrow(2, 34, 2).mul_(0.05);
  x.narrow(2, 36, 1).mul_(0.01);
  return x.contiguous();
}

TEST(VqVae, AbsoluteFromCanonicalIsTheClipInverse) {
  // G⁻¹ on tensors against motion/'s FromCanonical, from a clip's own
  // first frame (zero deltas) placed at root 0 and scale 1.
  torch::Tensor x = SyntheticFeatures(1, 20, 0);
  x.select(1, 0).narrow(1, 34, 3).zero_();
  const torch::Tensor absolute = AbsoluteFromCanonical(x, 17);
  const Clip2D clip = FromCanonical(
      CanonicalFromFeatures(x.data_ptr<float>(), 20, Coco17Layout(), 30.0,
                            Eigen::Vector2d::Zero(), 1.0));
  for (int t = 0; t < 20; ++t) {
    for (int j = 0; j < 17; ++j) {
      EXPECT_NEAR(absolute[0][t][j][0].item<float>(),
                  clip.keypoints.at(t, j).x_px, 1e-4);
      EXPECT_NEAR(absolute[0][t][j][1].item<float>(),
                  clip.keypoints.at(t, j).y_px, 1e-4);
    }
  }
}

TEST(VqVae, CodebookResetsDeadCodesOntoNewData) {
  // The codes settle on 4 clusters; then the data moves to 4 other
  // clusters far away. Codes no vector chooses any more fade (moving count
  // < 1), are reset onto the new data, and every new cluster gets a code.
  torch::manual_seed(3);
  auto generator = at::make_generator<at::CPUGeneratorImpl>(5);
  Codebook codebook(8, 2, 0.9);
  auto batch_of = [](const torch::Tensor& centres) {
    torch::Tensor which = torch::randint(centres.size(0), {256}, torch::kLong);
    return centres.index_select(0, which) + 0.02 * torch::randn({256, 2});
  };
  const torch::Tensor old_centres = torch::randn({4, 2}) * 5.0;
  const torch::Tensor new_centres = torch::randn({4, 2}) * 5.0 + 50.0;
  for (int step = 0; step < 100; ++step)
    codebook->Update(batch_of(old_centres), generator);
  int resets = 0;
  CodebookStats stats;
  for (int step = 0; step < 300; ++step) {
    stats = codebook->Update(batch_of(new_centres), generator);
    resets += stats.reset_codes;
  }
  EXPECT_GT(resets, 0);
  EXPECT_GE(stats.used_codes, 4);
  EXPECT_GT(stats.perplexity, 3.5);  // the 4 clusters are used about evenly
  const torch::Tensor codes = codebook->Lookup(torch::arange(8, torch::kLong));
  const torch::Tensor nearest_code =
      std::get<0>(torch::cdist(new_centres, codes).min(1));
  EXPECT_LT(nearest_code.max().item<float>(), 0.1);
}

TEST(VqVae, OverfitsATinySet) {
  // 4 windows of 32 frames: a small tokenizer must reproduce them almost
  // exactly once trained (tokens are 4 frames each, 8 per window, out of
  // 64 codes), through the quantization.
  torch::manual_seed(1);
  torch::set_num_threads(1);
  VqVaeOptions options;
  options.num_codes = 64;
  options.code_size = 32;
  options.width = 64;
  options.residual_depth = 2;
  VqVae model(37, options);
  torch::optim::AdamW optimizer(model->parameters(),
                                torch::optim::AdamWOptions(1e-3));
  auto generator = at::make_generator<at::CPUGeneratorImpl>(2);
  const torch::Tensor x = SyntheticFeatures(4, 32, 0);
  const torch::Tensor mean = torch::zeros({37}), std = torch::ones({37});
  double first = 0, last = 0;
  for (int step = 0; step < 300; ++step) {
    VqVaeImpl::Output out = model->Forward(x, &generator);
    VqVaeLosses losses = ComputeVqVaeLosses(
        out.reconstruction, x, out.commit_loss, mean, std, 17, options);
    optimizer.zero_grad();
    losses.total.backward();
    optimizer.step();
    if (step == 0) first = losses.canonical.item<double>();
    last = losses.canonical.item<double>();
  }
  // Through Encode/Decode (no straight-through): the mean absolute error
  // of X^can, whose channels span about ±0.5.
  model->eval();
  const torch::Tensor tokens = model->Encode(x);
  EXPECT_EQ(tokens.size(1), 8);
  const double error = (model->Decode(tokens) - x).abs().mean().item<double>();
  std::printf("canonical loss %.5f -> %.5f; decoded mean |error| %.4f\n", first,
              last, error);
  EXPECT_LT(last, 0.05 * first);
  EXPECT_LT(error, 0.05);
}

}  // namespace
}  // namespace m2d
