// gen: the generator's checkpoints — the tokenizer (VQ-VAE with the
// dataset's normalization) and the prior (GPT), each with its optimizer,
// step and random state, in verified archives (rl/archive_file.h).
#ifndef MIMIC2D_GEN_GEN_CHECKPOINT_H_
#define MIMIC2D_GEN_GEN_CHECKPOINT_H_

#include <torch/torch.h>

#include <string>

#include "gen/gen_config.h"
#include "gen/gpt.h"
#include "gen/vqvae.h"

namespace m2d {

// Where a stage stands.
struct GenStageState {
  int64_t step = 0;
  double seconds = 0.0;
  torch::Tensor generator_state;  // the batch sampler's random state
};

struct LoadedTokenizer {
  GenConfig config;
  VqVae model{nullptr};
  torch::Tensor mean, std;  // [C]: normalization of X^can
};

struct LoadedPrior {
  GenConfig config;
  Gpt model{nullptr};
};

// Both write atomically; `optimizer` may be null (weights only).
void SaveTokenizer(const std::string& path, const GenConfig& config,
                   VqVae& model, const torch::Tensor& mean,
                   const torch::Tensor& std, torch::optim::Optimizer* optimizer,
                   const GenStageState& state);
void SavePrior(const std::string& path, const GenConfig& config, Gpt& model,
               torch::optim::Optimizer* optimizer, const GenStageState& state);

// A model built from the checkpoint's own config, with its weights (and
// the tokenizer's normalization): for generation. InputError naming the
// file when it is not such a checkpoint or is damaged.
LoadedTokenizer LoadTokenizer(const std::string& path);
LoadedPrior LoadPrior(const std::string& path);

// Resume: the weights into `model` (built from the same config), the
// optimizer's state and the stage's. InputError naming the file when the
// shapes differ (a checkpoint of another config).
void ResumeTokenizer(const std::string& path, VqVae& model,
                     torch::optim::Optimizer& optimizer, GenStageState* state);
void ResumePrior(const std::string& path, Gpt& model,
                 torch::optim::Optimizer& optimizer, GenStageState* state);

}  // namespace m2d

#endif  // MIMIC2D_GEN_GEN_CHECKPOINT_H_
