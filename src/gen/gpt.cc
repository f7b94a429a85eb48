#include "gen/gpt.h"

#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/error.h"

namespace m2d {
namespace F = torch::nn::functional;

CausalBlockImpl::CausalBlockImpl(int embedding, int num_heads, double dropout)
    : num_heads_(num_heads) {
  attention_norm_ = register_module(
      "attention_norm",
      torch::nn::LayerNorm(torch::nn::LayerNormOptions({embedding})));
  attention_ = register_module(
      "attention",
      torch::nn::MultiheadAttention(
          torch::nn::MultiheadAttentionOptions(embedding, num_heads)
              .dropout(dropout)));
  mlp_norm_ = register_module(
      "mlp_norm",
      torch::nn::LayerNorm(torch::nn::LayerNormOptions({embedding})));
  mlp_in_ =
      register_module("mlp_in", torch::nn::Linear(embedding, 4 * embedding));
  mlp_out_ =
      register_module("mlp_out", torch::nn::Linear(4 * embedding, embedding));
  dropout_ = register_module("dropout", torch::nn::Dropout(dropout));
}

torch::Tensor CausalBlockImpl::forward(const torch::Tensor& x,
                                       const torch::Tensor& mask) {
  torch::Tensor h = attention_norm_->forward(x);
  torch::Tensor attended =
      std::get<0>(attention_->forward(h, h, h, /*key_padding_mask=*/{},
                                      /*need_weights=*/false, mask));
  torch::Tensor y = x + dropout_->forward(attended);
  torch::Tensor m = F::gelu(mlp_in_->forward(mlp_norm_->forward(y)));
  return y + dropout_->forward(mlp_out_->forward(m));
}

torch::Tensor CausalBlockImpl::Step(const torch::Tensor& x, torch::Tensor* keys,
                                    torch::Tensor* values) {
  // Outline: the attention of MultiheadAttention written out on its own
  // weights (queries of the new tokens against every cached and new key,
  // causal among the new ones), then the MLP, both pre-LN as forward().
  const int64_t length = x.size(0);
  const int64_t embedding = x.size(1);
  const int64_t head_size = embedding / num_heads_;
  torch::Tensor h = attention_norm_->forward(x);
  std::vector<torch::Tensor> qkv =
      F::linear(h, attention_->in_proj_weight, attention_->in_proj_bias)
          .chunk(3, -1);
  auto heads = [&](const torch::Tensor& t) {  // [S, E] -> [H, S, E/H]
    return t.view({length, num_heads_, head_size}).transpose(0, 1);
  };
  const torch::Tensor query = heads(qkv[0]);
  *keys = keys->defined() ? torch::cat({*keys, heads(qkv[1])}, 1)
                          : heads(qkv[1]).contiguous();
  *values = values->defined() ? torch::cat({*values, heads(qkv[2])}, 1)
                              : heads(qkv[2]).contiguous();
  torch::Tensor scores = torch::matmul(query, keys->transpose(1, 2)) /
                         std::sqrt(static_cast<double>(head_size));
  if (length > 1) {
    const int64_t total = keys->size(1);
    scores = scores + torch::full({length, total},
                                  -std::numeric_limits<float>::infinity())
                          .triu(total - length + 1);
  }
  torch::Tensor attended = torch::matmul(torch::softmax(scores, -1), *values)
                               .transpose(0, 1)
                               .reshape({length, embedding});
  attended = attention_->out_proj->forward(attended);
  torch::Tensor y = x + attended;
  torch::Tensor m = F::gelu(mlp_in_->forward(mlp_norm_->forward(y)));
  return y + mlp_out_->forward(m);
}

GptImpl::GptImpl(int num_codes, const GptOptions& options, int num_views)
    : num_codes_(num_codes), num_views_(num_views), options_(options) {
  const int embedding = options.embedding;
  token_embedding_ = register_module(
      "token_embedding",
      torch::nn::Embedding(num_codes + 1 + num_views, embedding));
  position_embedding_ = register_parameter(
      "position_embedding", torch::zeros({options.context_tokens, embedding}));
  for (int i = 0; i < options.num_layers; ++i) {
    blocks_.push_back(register_module(
        "block" + std::to_string(i),
        CausalBlock(embedding, options.num_heads, options.dropout)));
  }
  final_norm_ = register_module(
      "final_norm",
      torch::nn::LayerNorm(torch::nn::LayerNormOptions({embedding})));
  head_ = register_module(
      "head", torch::nn::Linear(
                  torch::nn::LinearOptions(embedding, num_codes).bias(false)));
  dropout_ = register_module("dropout", torch::nn::Dropout(options.dropout));
  // GPT-2's initialization: N(0, 0.02) weights, zero biases.
  torch::NoGradGuard no_grad;
  for (auto& parameter : named_parameters()) {
    const std::string& name = parameter.key();
    if (name.find("norm") != std::string::npos) continue;
    if (name.size() >= 4 && name.compare(name.size() - 4, 4, "bias") == 0) {
      parameter.value().zero_();
    } else {
      parameter.value().normal_(0.0, 0.02);
    }
  }
}

torch::Tensor GptImpl::forward(const torch::Tensor& tokens) {
  const int64_t length = tokens.size(1);
  TORCH_CHECK(length <= options_.context_tokens, "GPT input of ", length,
              " tokens exceeds the context of ", options_.context_tokens);
  torch::Tensor x = token_embedding_->forward(tokens) +
                    position_embedding_.narrow(0, 0, length).unsqueeze(0);
  x = dropout_->forward(x).transpose(0, 1);  // [S, B, E]
  torch::Tensor mask =
      torch::full({length, length}, -std::numeric_limits<float>::infinity())
          .triu(1);
  for (CausalBlock& block : blocks_) x = block->forward(x, mask);
  return head_->forward(final_norm_->forward(x.transpose(0, 1)));
}

torch::Tensor GptImpl::ForwardCached(const torch::Tensor& tokens,
                                     GptCache* cache) {
  const int64_t count = tokens.size(0);
  TORCH_CHECK(cache->length + count <= options_.context_tokens,
              "cached GPT input of ", cache->length + count,
              " tokens exceeds the context of ", options_.context_tokens);
  if (cache->keys.empty()) {
    cache->keys.resize(blocks_.size());
    cache->values.resize(blocks_.size());
  }
  torch::Tensor x = token_embedding_->forward(tokens) +
                    position_embedding_.narrow(0, cache->length, count);
  for (size_t b = 0; b < blocks_.size(); ++b)
    x = blocks_[b]->Step(x, &cache->keys[b], &cache->values[b]);
  cache->length += count;
  return head_->forward(final_norm_->forward(x[count - 1]));
}

TokenBatch SampleTokenBatch(const std::vector<std::vector<int64_t>>& sequences,
                            int num_codes, int context, int batch_size,
                            double keep_probability,
                            torch::Generator& generator,
                            const std::vector<int64_t>& conditions) {
  TORCH_CHECK(!sequences.empty(), "no token sequences to sample from");
  TORCH_CHECK(conditions.empty() || conditions.size() == sequences.size(),
              "one condition per token sequence");
  const int64_t start = num_codes;
  // Slot 0 holds the condition; the read sequence fills the rest.
  const int64_t slots = conditions.empty() ? 0 : 1;
  const int64_t span = context - slots;
  torch::Tensor inputs = torch::zeros({batch_size, context}, torch::kLong);
  torch::Tensor targets =
      torch::full({batch_size, context}, kIgnoreTarget, torch::kLong);
  auto draw = [&](int64_t bound) {  // uniform in [0, bound)
    return torch::randint(bound, {1}, generator, torch::kLong).item<int64_t>();
  };
  for (int b = 0; b < batch_size; ++b) {
    const int64_t drawn = draw(static_cast<int64_t>(sequences.size()));
    const std::vector<int64_t>& codes = sequences[drawn];
    // The read sequence [start, c_0, ..., c_{n-1}] has n + 1 tokens; a
    // window of `span` of them predicts the token after each of them.
    const int64_t read_length = static_cast<int64_t>(codes.size()) + 1;
    const int64_t offset = draw(std::max<int64_t>(1, read_length - span));
    auto token_at = [&](int64_t i) { return i == 0 ? start : codes[i - 1]; };
    int64_t* input = inputs[b].data_ptr<int64_t>();
    int64_t* target = targets[b].data_ptr<int64_t>();
    if (slots > 0) {
      input[0] = conditions[drawn];
      if (offset > 0) target[0] = token_at(offset);
    }
    for (int64_t s = 0; s < span && offset + s + 1 < read_length; ++s) {
      input[slots + s] = token_at(offset + s);
      target[slots + s] = token_at(offset + s + 1);
    }
  }
  if (keep_probability < 1.0) {
    torch::Tensor corrupt =
        torch::rand({batch_size, context}, generator) >= keep_probability;
    corrupt = corrupt.logical_and(inputs < start);  // codes only
    inputs = torch::where(corrupt,
                          torch::randint(num_codes, {batch_size, context},
                                         generator, torch::kLong),
                          inputs);
  }
  return {inputs, targets};
}

TokenSplit SplitTokensForValidation(
    const std::vector<std::vector<int64_t>>& sequences, int context,
    const std::vector<int64_t>& conditions) {
  TORCH_CHECK(conditions.empty() || conditions.size() == sequences.size(),
              "one condition per token sequence");
  TokenSplit split;
  std::vector<torch::Tensor> inputs, targets;
  for (size_t i = 0; i < sequences.size(); ++i) {
    const std::vector<int64_t>& codes = sequences[i];
    const int64_t n = static_cast<int64_t>(codes.size());
    if (n < 2 * context + 1) {
      split.training.push_back(codes);
      continue;
    }
    split.training.emplace_back(codes.begin(), codes.end() - context);
    // Inputs: the code before the held-out ones (or the condition) and all
    // but the last of them.
    std::vector<int64_t> input(codes.end() - context - 1, codes.end() - 1);
    if (!conditions.empty()) input.front() = conditions[i];
    inputs.push_back(torch::tensor(input, torch::kLong));
    targets.push_back(
        torch::tensor(std::vector<int64_t>(codes.end() - context, codes.end()),
                      torch::kLong));
  }
  if (!inputs.empty()) {
    split.validation.inputs = torch::stack(inputs);
    split.validation.targets = torch::stack(targets);
  }
  return split;
}

torch::Tensor NextTokenLoss(const torch::Tensor& logits,
                            const torch::Tensor& targets) {
  return F::cross_entropy(
      logits.reshape({-1, logits.size(2)}), targets.reshape({-1}),
      F::CrossEntropyFuncOptions().ignore_index(kIgnoreTarget));
}

TokenSampler::TokenSampler(Gpt gpt, SamplingOptions options, uint64_t seed,
                           int view)
    : gpt_(std::move(gpt)),
      options_(options),
      generator_(at::make_generator<at::CPUGeneratorImpl>(seed)) {
  options_.Validate();
  if (gpt_->num_views() > 0) {
    if (view < 0 || view >= gpt_->num_views())
      throw ConfigError("sampling: the prior is conditioned on " +
                        std::to_string(gpt_->num_views()) + " views; view " +
                        std::to_string(view) + " is not one of them");
    condition_.push_back(gpt_->view_token(view));
  } else if (view >= 0) {
    throw ConfigError("sampling: view " + std::to_string(view) +
                      " asked of a prior not conditioned on the view");
  }
  // The codes one attention window holds after the condition.
  const int code_context =
      gpt_->context_tokens() - static_cast<int>(condition_.size());
  kept_codes_ = options_.kept_context_tokens > 0 ? options_.kept_context_tokens
                                                 : gpt_->context_tokens() / 2;
  if (kept_codes_ >= code_context)
    throw ConfigError("sampling: kept_context_tokens " +
                      std::to_string(kept_codes_) +
                      " must be below the prior's context of " +
                      std::to_string(code_context) + " codes");
  history_.push_back(gpt_->start_token());
}

int64_t TokenSampler::Next() {
  // Inference only: no autograd bookkeeping on any tensor made here.
  c10::InferenceMode inference;
  gpt_->eval();
  // Outline: feed the cache what it has not seen (everything since a
  // restart, or the last code); draw from the logits; append.
  const int64_t context = gpt_->context_tokens();
  torch::Tensor logits;
  if (cache_.length == 0 || cache_.length == context) {
    // A restart: the condition and the kept codes (all of a short
    // history).
    const int64_t keep = std::min<int64_t>(
        static_cast<int64_t>(history_.size()),
        cache_.length == context
            ? kept_codes_
            : context - static_cast<int64_t>(condition_.size()));
    std::vector<int64_t> tokens = condition_;
    tokens.insert(tokens.end(), history_.end() - keep, history_.end());
    cache_ = GptCache();
    logits = gpt_->ForwardCached(torch::tensor(tokens, torch::kLong), &cache_);
  } else {
    logits = gpt_->ForwardCached(
        torch::tensor(std::vector<int64_t>{history_.back()}, torch::kLong),
        &cache_);
  }
  logits = logits / options_.temperature;
  if (options_.top_k > 0 && options_.top_k < logits.size(0)) {
    const float threshold =
        std::get<0>(logits.topk(options_.top_k)).min().item<float>();
    logits = logits.masked_fill(logits < threshold,
                                -std::numeric_limits<float>::infinity());
  }
  const int64_t code =
      torch::multinomial(torch::softmax(logits, 0), 1, false, generator_)
          .item<int64_t>();
  history_.push_back(code);
  // The history only needs the attended window.
  if (history_.size() > static_cast<size_t>(4 * context))
    history_.erase(history_.begin(), history_.end() - context);
  codes_.push_back(code);
  return code;
}

}  // namespace m2d
