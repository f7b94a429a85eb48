#include "gen/feature_encoder.h"

#include <ATen/CPUGeneratorImpl.h>

#include "common/error.h"

namespace m2d {
namespace F = torch::nn::functional;

namespace {
constexpr int kLevels = 3;  // stride-2 convolutions: W / 8 positions
}  // namespace

FeatureEncoderImpl::FeatureEncoderImpl(int frame_size,
                                       const FeatureEncoderOptions& options)
    : options_(options), frame_size_(frame_size) {
  if (options.window_frames % (1 << kLevels) != 0)
    throw ConfigError("feature encoder: window_frames must be a multiple of 8");
  const int width = options.width;
  const int positions = options.window_frames >> kLevels;
  for (int level = 0; level < kLevels; ++level) {
    down_.push_back(register_module(
        "down" + std::to_string(level),
        torch::nn::Conv1d(
            torch::nn::Conv1dOptions(level == 0 ? frame_size : width, width, 4)
                .stride(2)
                .padding(1))));
    up_.push_back(register_module(
        "up" + std::to_string(level),
        torch::nn::Conv1d(
            torch::nn::Conv1dOptions(width, width, 3).padding(1))));
  }
  to_features_ = register_module(
      "to_features", torch::nn::Linear(width * positions, options.features));
  from_features_ = register_module(
      "from_features", torch::nn::Linear(options.features, width * positions));
  out_ = register_module(
      "out", torch::nn::Conv1d(
                 torch::nn::Conv1dOptions(width, frame_size, 3).padding(1)));
}

torch::Tensor FeatureEncoderImpl::Encode(const torch::Tensor& x) {
  torch::Tensor h = x.transpose(1, 2);
  for (auto& conv : down_) h = torch::relu(conv->forward(h));
  return to_features_->forward(h.flatten(1));
}

torch::Tensor FeatureEncoderImpl::Reconstruct(const torch::Tensor& x) {
  const int positions = options_.window_frames >> kLevels;
  torch::Tensor h = torch::relu(from_features_->forward(Encode(x)))
                        .reshape({x.size(0), options_.width, positions});
  for (auto& conv : up_) {
    h = F::interpolate(h, F::InterpolateFuncOptions()
                              .scale_factor(std::vector<double>{2.0})
                              .mode(torch::kNearest));
    h = torch::relu(conv->forward(h));
  }
  return out_->forward(h).transpose(1, 2);
}

torch::Tensor DatasetWindows(const std::vector<GenSequence>& sequences,
                             int frame_size, int window_frames,
                             int stride_frames, const torch::Tensor& mean,
                             const torch::Tensor& std) {
  std::vector<torch::Tensor> windows;
  for (const GenSequence& sequence : sequences) {
    torch::Tensor frames =
        torch::from_blob(const_cast<float*>(sequence.features.data()),
                         {sequence.num_frames, frame_size});
    for (int start = 0; start + window_frames <= sequence.num_frames;
         start += stride_frames) {
      windows.push_back(frames.narrow(0, start, window_frames));
    }
  }
  if (windows.empty())
    throw ConfigError("no sequence is as long as a feature window (" +
                      std::to_string(window_frames) + " frames)");
  return (torch::stack(windows) - mean) / std;
}

FeatureEncoder TrainFeatureEncoder(const torch::Tensor& windows, int frame_size,
                                   const FeatureEncoderOptions& options,
                                   uint64_t seed, double* final_loss) {
  torch::AutoGradMode grad_mode(true);  // even under a caller's NoGradGuard
  torch::manual_seed(seed);
  FeatureEncoder encoder(frame_size, options);
  torch::optim::AdamW optimizer(
      encoder->parameters(), torch::optim::AdamWOptions(options.learning_rate));
  torch::Generator generator = at::make_generator<at::CPUGeneratorImpl>(seed);
  double loss_value = 0.0;
  for (int64_t step = 0; step < options.steps; ++step) {
    torch::Tensor batch = windows.index_select(
        0, torch::randint(windows.size(0), {options.batch_size}, generator,
                          torch::kLong));
    torch::Tensor loss = F::mse_loss(encoder->Reconstruct(batch), batch);
    optimizer.zero_grad();
    loss.backward();
    optimizer.step();
    loss_value = loss.item<double>();
  }
  if (final_loss != nullptr) *final_loss = loss_value;
  encoder->eval();
  return encoder;
}

Eigen::MatrixXd EncodeWindows(FeatureEncoder& encoder,
                              const torch::Tensor& windows) {
  torch::NoGradGuard no_grad;
  torch::Tensor features =
      encoder->Encode(windows).to(torch::kDouble).contiguous();
  Eigen::MatrixXd rows(features.size(0), features.size(1));
  // Row-major tensor into a column-major matrix.
  const double* data = features.data_ptr<double>();
  for (int64_t i = 0; i < features.size(0); ++i)
    for (int64_t j = 0; j < features.size(1); ++j)
      rows(i, j) = data[i * features.size(1) + j];
  return rows;
}

}  // namespace m2d
