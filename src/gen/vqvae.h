// gen: the tokenizer — a VQ-VAE over windows of X^can (1D convolutions in
// time, a codebook kept by moving averages with dead-code resets; T2M-GPT's
// design at the paper's sizes) and its losses.
#ifndef MIMIC2D_GEN_VQVAE_H_
#define MIMIC2D_GEN_VQVAE_H_

#include <torch/torch.h>

#include <vector>

#include "gen/gen_config.h"
#include "gen/motion_dataset.h"

namespace m2d {

// G⁻¹ for batches of windows: features [B, T, 2J + 3] (not normalized; the
// rows of CanonicalFeatures) to absolute keypoints [B, T, J, 2], in units of
// the scale before the window with the root before it at 0. Frame t applies
// its deltas to frame t − 1's root and scale, frame 0 to (0, 1): for a
// clip's own first frame (zero deltas) this is FromCanonical with
// first_root 0 and first_scale 1. Differentiable.
torch::Tensor AbsoluteFromCanonical(const torch::Tensor& features,
                                    int num_keypoints);

// Dilated residual blocks, x + W₂ ReLU(W₁ ReLU(x)) with W₁ a kernel-3
// convolution of dilation 3^(depth−1), ..., 9, 3, 1 and W₂ a kernel-1 one.
class ResidualStackImpl : public torch::nn::Module {
 public:
  ResidualStackImpl(int width, int depth);
  torch::Tensor forward(torch::Tensor x);  // [B, width, T]

 private:
  std::vector<torch::nn::Conv1d> dilated_, pointwise_;
};
TORCH_MODULE(ResidualStack);

struct CodebookStats {
  double perplexity = 0.0;  // exp(entropy) of the batch's code counts (<= K)
  int used_codes = 0;       // codes chosen at least once in the batch
  int reset_codes = 0;      // dead codes (moving count < 1) replaced
};

// K codes of size D. Training moves each code toward the mean of the
// vectors assigned to it (moving averages of counts and sums) and replaces
// a code whose moving count fell below 1 by a random vector of the batch,
// its averages restarted there; the first training batch seeds every code.
class CodebookImpl : public torch::nn::Module {
 public:
  CodebookImpl(int num_codes, int code_size, double ema_decay);

  torch::Tensor Nearest(const torch::Tensor& z) const;  // [N, D] -> [N]
  torch::Tensor Lookup(
      const torch::Tensor& indices) const;  // [...] -> [..., D]
  // One training step on the batch's encoder outputs z [N, D].
  CodebookStats Update(const torch::Tensor& z, torch::Generator& generator);
  int num_codes() const { return num_codes_; }

 private:
  int num_codes_;
  double ema_decay_;
  torch::Tensor codes_, ema_count_, ema_sum_, seeded_;
};
TORCH_MODULE(Codebook);

class VqVaeImpl : public torch::nn::Module {
 public:
  VqVaeImpl(int frame_size, const VqVaeOptions& options);

  struct Output {
    torch::Tensor reconstruction;  // [B, T, C], normalized like the input
    torch::Tensor tokens;          // [B, T / frames_per_token]
    torch::Tensor commit_loss;     // mean |z - sg(q)|^2
    CodebookStats stats;           // of the codebook update (training)
  };
  // x: [B, T, C] normalized features, T a multiple of frames_per_token.
  // With a generator (training) the codebook is updated first (as
  // T2M-GPT); the decoder gets q through the straight-through estimator.
  Output Forward(const torch::Tensor& x, torch::Generator* training);

  torch::Tensor Encode(const torch::Tensor& x);       // -> tokens [B, N]
  torch::Tensor Decode(const torch::Tensor& tokens);  // -> [B, N * f, C]

  int frame_size() const { return frame_size_; }
  int frames_per_token() const { return options_.frames_per_token(); }
  int num_codes() const { return options_.num_codes; }
  const VqVaeOptions& options() const { return options_; }

 private:
  torch::Tensor EncodeLatents(const torch::Tensor& x);  // [B, N, D]
  torch::Tensor DecodeLatents(const torch::Tensor& q);  // [B, N, D] -> x

  int frame_size_;
  VqVaeOptions options_;
  torch::nn::Conv1d encoder_in_{nullptr}, encoder_out_{nullptr};
  std::vector<torch::nn::Conv1d> encoder_down_;
  std::vector<ResidualStack> encoder_blocks_, decoder_blocks_;
  torch::nn::Conv1d decoder_in_{nullptr}, decoder_hidden_{nullptr},
      decoder_out_{nullptr};
  std::vector<torch::nn::Conv1d> decoder_up_;
  Codebook codebook_{nullptr};
};
TORCH_MODULE(VqVae);

struct VqVaeLosses {
  torch::Tensor total;
  torch::Tensor canonical;  // smooth L1 on normalized X^can
  torch::Tensor absolute;   // smooth L1 on G⁻¹ (units of body scale)
  torch::Tensor velocity;   // smooth L1 on frame differences of x̄
  torch::Tensor commit;
};

// The paper's L_rec = |X^can − X̂^can| + ω |G⁻¹(X^can) − G⁻¹(X̂^can)|, plus
// T2M-GPT's velocity and commitment terms. `mean`/`std` [C] undo the
// normalization before G⁻¹.
VqVaeLosses ComputeVqVaeLosses(const torch::Tensor& reconstruction,
                               const torch::Tensor& target,
                               const torch::Tensor& commit_loss,
                               const torch::Tensor& mean,
                               const torch::Tensor& std, int num_keypoints,
                               const VqVaeOptions& options);

// Every sequence's codes, each sequence encoded whole (its frames cut to a
// multiple of the token length; normalized by `mean`, `std`), in eval mode
// (the model's mode is restored after); `kept` gets the index in
// dataset.sequences of each sequence long enough for a code. The prior
// learns these codes.
std::vector<std::vector<int64_t>> TokenizeDataset(VqVae& model,
                                                  const GenDataset& dataset,
                                                  const torch::Tensor& mean,
                                                  const torch::Tensor& std,
                                                  std::vector<int>* kept);

}  // namespace m2d

#endif  // MIMIC2D_GEN_VQVAE_H_
