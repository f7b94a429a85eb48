// rl: the actor-critic networks. The 2D block of the observation (current
// projection + future reference, per view) goes through an encoder phi;
// phi's features are averaged over the K views given (K = 1 in training,
// K > 1 for zero-shot multi-view tracking); proprioception and object state
// join after phi, and for the critic alone the critic-only block when the
// observation has one. Policy: MLP -> Gaussian mean over normalized PD
// targets.
#ifndef MIMIC2D_RL_NETWORKS_H_
#define MIMIC2D_RL_NETWORKS_H_

#include <torch/torch.h>

#include "env/observation.h"
#include "rl/train_config.h"

namespace m2d {

// Running mean and variance of observation features (Chan et al.'s
// parallel update), kept as buffers so they are saved with the model.
// Normalized features are clipped to +-clip_std (a setting, not saved: the
// config rebuilds it).
class RunningNormalizerImpl : public torch::nn::Module {
 public:
  RunningNormalizerImpl(int size, double clip_std);
  void Update(const torch::Tensor& batch);                // [B, size]
  torch::Tensor Normalize(const torch::Tensor& x) const;  // clipped

  torch::Tensor mean, variance, count;
  double clip_std;
};
TORCH_MODULE(RunningNormalizer);

// Linear layers with ReLU between them (none after the last).
torch::nn::Sequential MakeMlp(int input, const std::vector<int>& hidden,
                              int output, double last_layer_gain);

class ActorCriticImpl : public torch::nn::Module {
 public:
  ActorCriticImpl(const ObservationLayout& layout, const ModelOptions& options,
                  int action_size);

  // Raw observations [B, base + K * view] -> normalized (same shape).
  torch::Tensor Normalize(const torch::Tensor& raw) const;
  void UpdateNormalizer(const torch::Tensor& raw);

  // On normalized observations with `num_views` view blocks.
  torch::Tensor ActionMean(const torch::Tensor& obs, int num_views = 1);
  torch::Tensor Value(const torch::Tensor& obs, int num_views = 1);  // [B]
  torch::Tensor LogStd() const { return log_std; }

  // Log-density of `actions` under N(mean, sigma) summed over dimensions.
  torch::Tensor LogProb(const torch::Tensor& mean,
                        const torch::Tensor& actions) const;
  torch::Tensor Entropy() const;  // of the diagonal Gaussian, scalar

  const ObservationLayout& layout() const { return layout_; }
  int action_size() const { return action_size_; }

 private:
  // phi averaged over the views, joined with the first `base_width` base
  // features (the policy's, or all of them for the critic).
  torch::Tensor Features(torch::nn::Sequential& encoder,
                         const torch::Tensor& obs, int num_views,
                         int base_width);

  ObservationLayout layout_;
  int base_size_;
  int action_size_;
  RunningNormalizer base_normalizer{nullptr}, view_normalizer{nullptr};
  torch::nn::Sequential actor_encoder{nullptr}, critic_encoder{nullptr};
  torch::nn::Sequential actor{nullptr}, critic{nullptr};
  torch::Tensor log_std;
};
TORCH_MODULE(ActorCritic);

// Copies `source`'s weights and observation statistics into `target`, whose
// layout differs from the source's only by more future reference frames
// (`run.init_from` a checkpoint trained with a shorter horizon). The
// encoders' first layers keep the source's weights for the frames it read
// and start at zero for the new ones, so `target` acts and values exactly as
// `source` until training moves those weights; the new frames' normalizer
// statistics start as the source's last future frame's. ConfigError naming
// what differs when the layouts or networks differ otherwise.
void WidenFutureFrames(ActorCriticImpl& source, ActorCriticImpl& target);

// Within its scope (on this thread: autocast state is thread-local), matrix
// products run in bfloat16 when the precision says so (LibTorch's CPU
// autocast; oneDNN uses AMX or AVX512-BF16 where the CPU has them); weights
// stay float32. The collector and the update both act in it, so that the
// behavior policy's stored log-probabilities and the update's agree: with
// sigma = 0.05, a mean rounded differently would read as a policy ratio
// several percent from 1 before any step.
//
// Scopes nest: one opened while another is open on the thread does nothing.
// Autocast keeps each weight's bfloat16 copy until the outermost scope
// closes, so a scope around a whole rollout (weights fixed) casts the
// weights once instead of at every step; the update opens one per gradient
// step, as its weights change after each.
class PrecisionScope {
 public:
  explicit PrecisionScope(TrainingPrecision precision);
  ~PrecisionScope();
  PrecisionScope(const PrecisionScope&) = delete;
  PrecisionScope& operator=(const PrecisionScope&) = delete;

 private:
  bool bf16_;
};

// The Gaussian mean and the value of `obs` (normalized) in the training
// precision, returned as float32: what the collector acts with and the
// update differentiates.
void ForwardInPrecision(ActorCritic& model, const torch::Tensor& obs,
                        TrainingPrecision precision, torch::Tensor* mean,
                        torch::Tensor* value);

}  // namespace m2d

#endif  // MIMIC2D_RL_NETWORKS_H_
