// gen: the prior — a GPT-style causal transformer over the tokenizer's
// codes, p(c) = Π p(c_i | c_<i), sampled with temperature and top-k from a
// sliding context so that generation never ends.
#ifndef MIMIC2D_GEN_GPT_H_
#define MIMIC2D_GEN_GPT_H_

#include <torch/torch.h>

#include <cstdint>
#include <vector>

#include "gen/gen_config.h"

namespace m2d {

// Pre-LN block: x + attention(LN(x)), then x + MLP(LN(x)) (GELU, 4x wide).
// LibTorch 1.13's TransformerEncoderLayer is post-LN only.
class CausalBlockImpl : public torch::nn::Module {
 public:
  CausalBlockImpl(int embedding, int num_heads, double dropout);
  // x: [S, B, E]; mask: [S, S] additive (-inf above the diagonal).
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& mask);
  // Inference on new tokens x [S, E] (one sequence) that follow the ones
  // whose attention keys and values are in `keys`, `values` ([H, L, E/H],
  // undefined when L = 0); appends the new tokens' to them. The same
  // numbers as forward() on the whole sequence, with the mask.
  torch::Tensor Step(const torch::Tensor& x, torch::Tensor* keys,
                     torch::Tensor* values);

 private:
  torch::nn::LayerNorm attention_norm_{nullptr}, mlp_norm_{nullptr};
  torch::nn::MultiheadAttention attention_{nullptr};
  torch::nn::Linear mlp_in_{nullptr}, mlp_out_{nullptr};
  torch::nn::Dropout dropout_{nullptr};
  int num_heads_;
};
TORCH_MODULE(CausalBlock);

// What incremental inference keeps of the tokens seen so far: per block,
// their attention keys and values; and how many there are (their positions
// are 0 .. length - 1).
struct GptCache {
  std::vector<torch::Tensor> keys, values;
  int64_t length = 0;
};

class GptImpl : public torch::nn::Module {
 public:
  // Vocabulary: the K codes, a start token (K) that opens a sequence and,
  // for a prior conditioned on the view, `num_views` view tokens (K + 1 +
  // v), one of which opens every window.
  GptImpl(int num_codes, const GptOptions& options, int num_views = 0);

  // tokens: [B, S] int64 in [0, K], S <= context_tokens -> logits over the
  // K codes [B, S, K] for each next token.
  torch::Tensor forward(const torch::Tensor& tokens);

  // Inference: appends `tokens` (a 1-D int64 tensor, at most the context
  // left in `cache`) to the cached sequence and returns the logits [K] for
  // the token after them. Matches forward() on the cached sequence.
  torch::Tensor ForwardCached(const torch::Tensor& tokens, GptCache* cache);

  int num_codes() const { return num_codes_; }
  int64_t start_token() const { return num_codes_; }
  int num_views() const { return num_views_; }
  int64_t view_token(int view) const { return num_codes_ + 1 + view; }
  int context_tokens() const { return options_.context_tokens; }

 private:
  int num_codes_;
  int num_views_;
  GptOptions options_;
  torch::nn::Embedding token_embedding_{nullptr};
  torch::Tensor position_embedding_;  // [context, E], learned
  std::vector<CausalBlock> blocks_;
  torch::nn::LayerNorm final_norm_{nullptr};
  torch::nn::Linear head_{nullptr};
  torch::nn::Dropout dropout_{nullptr};
};
TORCH_MODULE(Gpt);

// A training batch of token windows: inputs [B, S] and targets [B, S] (the
// next token; kIgnoreTarget where a short sequence ends).
inline constexpr int64_t kIgnoreTarget = -100;
struct TokenBatch {
  torch::Tensor inputs, targets;
};

// Draws `batch_size` windows of `context` tokens. Each sequence is read as
// [start, c_0, ..., c_{n-1}]; a window starts anywhere in it (so windows
// without the start token teach the sliding context of endless generation)
// and is padded when the sequence is shorter. With probability 1 −
// keep_probability an input code is replaced by a random code.
// `conditions` (empty, or one token per sequence: its view token) opens
// every window of its sequence in slot 0, followed by context − 1 tokens
// of the read sequence; slot 0 predicts the first of them (nothing when
// that is the start token).
TokenBatch SampleTokenBatch(const std::vector<std::vector<int64_t>>& sequences,
                            int num_codes, int context, int batch_size,
                            double keep_probability,
                            torch::Generator& generator,
                            const std::vector<int64_t>& conditions = {});

// The prior's held-out data: every sequence long enough (at least
// 2 * context + 1 codes) keeps its last `context` codes apart. `validation`
// holds one window per such sequence whose targets are exactly those codes
// (inputs: the code before them and all but the last of them; undefined
// tensors when no sequence is long enough); `training` is every sequence
// without its held-out codes, in order, so no held-out code is ever an
// input or a target of training. With `conditions` (as SampleTokenBatch
// takes them) a window's inputs are the sequence's condition and all but
// the last held-out code.
struct TokenSplit {
  std::vector<std::vector<int64_t>> training;
  TokenBatch validation;
};
TokenSplit SplitTokensForValidation(
    const std::vector<std::vector<int64_t>>& sequences, int context,
    const std::vector<int64_t>& conditions = {});

// Mean next-token cross-entropy (nats) of a batch.
torch::Tensor NextTokenLoss(const torch::Tensor& logits,
                            const torch::Tensor& targets);

// Endless sampling: the history starts with the start token; each step
// attends to the last context_tokens tokens of it (after the view token,
// for a prior conditioned on the view).
class TokenSampler {
 public:
  // `view`: which of the data's views to generate (a conditioned prior
  // needs one in [0, num_views); an unconditioned one takes -1).
  // ConfigError otherwise.
  TokenSampler(Gpt gpt, SamplingOptions options, uint64_t seed, int view = -1);
  int64_t Next();  // draws, appends and returns the next code
  const std::vector<int64_t>& codes() const { return codes_; }

 private:
  Gpt gpt_;
  SamplingOptions options_;
  torch::Generator generator_;
  std::vector<int64_t> history_;  // start token, then the codes
  std::vector<int64_t> codes_;
  std::vector<int64_t> condition_;  // the view token, or nothing
  int kept_codes_ = 0;              // codes kept when the context slides
  // The keys and values of the attended tokens (the tail of history_).
  // When the context is full, it restarts from its last half: each code
  // attends to between half the context and all of it, as training windows
  // that start mid-sequence do, and a code costs one token's pass instead
  // of the whole context's.
  GptCache cache_;
};

}  // namespace m2d

#endif  // MIMIC2D_GEN_GPT_H_
