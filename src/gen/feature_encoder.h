// gen: the motion feature encoder FID is measured with — windows of X^can
// to a feature vector, trained as an autoencoder on real 2D motion held
// apart from the generator's data — and the FID protocol itself.
#ifndef MIMIC2D_GEN_FEATURE_ENCODER_H_
#define MIMIC2D_GEN_FEATURE_ENCODER_H_

#include <torch/torch.h>

#include <Eigen/Core>
#include <vector>

#include "gen/motion_dataset.h"

namespace m2d {

struct FeatureEncoderOptions {
  int window_frames = 64;  // a multiple of 8
  int width = 128;
  int features = 64;  // the vector FID compares
  int batch_size = 64;
  int64_t steps = 3000;
  double learning_rate = 1e-3;
};

// Three stride-2 convolutions and a linear map to `features`; a mirror
// image decodes it back (for training only).
class FeatureEncoderImpl : public torch::nn::Module {
 public:
  FeatureEncoderImpl(int frame_size, const FeatureEncoderOptions& options);
  torch::Tensor Encode(const torch::Tensor& x);       // [B, W, C] -> [B, F]
  torch::Tensor Reconstruct(const torch::Tensor& x);  // [B, W, C] -> same

 private:
  FeatureEncoderOptions options_;
  int frame_size_;
  std::vector<torch::nn::Conv1d> down_, up_;
  torch::nn::Linear to_features_{nullptr}, from_features_{nullptr};
  torch::nn::Conv1d out_{nullptr};
};
TORCH_MODULE(FeatureEncoder);

// Every window of `window_frames` (stride `stride_frames`) of every
// sequence, normalized by `mean`/`std`: [N, W, C].
torch::Tensor DatasetWindows(const std::vector<GenSequence>& sequences,
                             int frame_size, int window_frames,
                             int stride_frames, const torch::Tensor& mean,
                             const torch::Tensor& std);

// Trains an encoder on `windows` (normalized) and returns it in eval mode;
// `final_loss`, when given, receives the last reconstruction MSE.
FeatureEncoder TrainFeatureEncoder(const torch::Tensor& windows, int frame_size,
                                   const FeatureEncoderOptions& options,
                                   uint64_t seed, double* final_loss = nullptr);

// The encoder's features of `windows`, as rows.
Eigen::MatrixXd EncodeWindows(FeatureEncoder& encoder,
                              const torch::Tensor& windows);

}  // namespace m2d

#endif  // MIMIC2D_GEN_FEATURE_ENCODER_H_
