// gen: training the generator — the tokenizer (VQ-VAE) on windows of the
// dataset, then the prior (GPT) on the tokenizer's codes of every sequence;
// CSV logs, atomic checkpoints and resume. This header does not include
// LibTorch.
#ifndef MIMIC2D_GEN_GEN_TRAINER_H_
#define MIMIC2D_GEN_GEN_TRAINER_H_

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "gen/gen_config.h"
#include "gen/motion_dataset.h"

namespace m2d {

enum class GenStage { kTokenizer, kPrior };
const char* SettingName(GenStage stage);

struct GenProgress {
  GenStage stage = GenStage::kTokenizer;
  int64_t step = 0;      // steps done in this stage
  int64_t steps = 0;     // the stage's total
  double seconds = 0.0;  // this stage's training time so far
  double learning_rate = 0.0;
  int torch_threads = 0;  // LibTorch's threads for the steps now
  double loss = 0.0;  // tokenizer: the total loss; prior: cross-entropy (nats)
  // Tokenizer: reconstruction terms and codebook use.
  double canonical_loss = 0.0, absolute_loss = 0.0, velocity_loss = 0.0,
         commit_loss = 0.0;
  double perplexity = 0.0;
  int used_codes = 0, reset_codes = 0;
  // Prior: share of next tokens predicted exactly (argmax), and the
  // cross-entropy on the held-out tail of every sequence (NaN when no
  // sequence is long enough to keep one; gpt.h's SplitTokensForValidation).
  double accuracy = 0.0;
  double validation_loss = std::numeric_limits<double>::quiet_NaN();
};

struct GenTrainSummary {
  bool interrupted = false;
  int64_t tokenizer_steps = 0, prior_steps = 0;
  // Last reported; NaN when the stage took no step in this run.
  double tokenizer_loss = std::numeric_limits<double>::quiet_NaN();
  double prior_loss = std::numeric_limits<double>::quiet_NaN();
  std::string tokenizer_path, prior_path;
  // A few lines: steps, final losses, codebook use, files.
  std::string BriefReport() const;
};

// Checkpoint file names inside run.run_dir.
inline constexpr char kTokenizerFile[] = "tokenizer.pt";
inline constexpr char kPriorFile[] = "prior.pt";

// Outline: train the tokenizer up to tokenizer.steps (from its checkpoint
// with `resume`), tokenize every sequence of `dataset`, train the prior up
// to prior.steps. Checkpoints every run.checkpoint_minutes, at each stage's
// end and when `stop` turns true (then it returns, interrupted). Logs:
// <run_dir>/tokenizer_log.csv and prior_log.csv. InputError naming the
// file when a checkpoint to resume is unreadable or belongs to another
// config's shapes.
GenTrainSummary TrainGenerator(
    const GenConfig& config, const GenDataset& dataset, bool resume,
    const std::atomic<bool>* stop,
    const std::function<void(const GenProgress&)>& on_progress);

}  // namespace m2d

#endif  // MIMIC2D_GEN_GEN_TRAINER_H_
