#include "gen/motion_stream.h"

#include <algorithm>

#include "common/error.h"

namespace m2d {

MotionStream::MotionStream(LoadedTokenizer tokenizer, LoadedPrior prior,
                           const MotionStreamOptions& options)
    : tokenizer_(std::move(tokenizer)),
      sampler_(prior.model, options.sampling, options.seed),
      options_(options) {
  if (prior.model->num_codes() != tokenizer_.model->num_codes()) {
    throw ConfigError("the prior predicts " +
                      std::to_string(prior.model->num_codes()) +
                      " codes but the tokenizer has " +
                      std::to_string(tokenizer_.model->num_codes()) +
                      ": they come from different runs");
  }
  const StreamDecoding& decoding = options_.decoding;
  if (decoding.lookahead_codes < 0 ||
      decoding.context_codes < decoding.lookahead_codes + 1)
    throw ConfigError(
        "stream: lookahead_codes must be >= 0 and context_codes > "
        "lookahead_codes");
  tokenizer_.model->eval();
}

void MotionStream::Next(std::vector<float>* rows) {
  torch::NoGradGuard no_grad;
  // Outline: draw codes until the lookahead after the next code to emit
  // exists; decode the latest codes; keep the frames of the code to emit.
  const int64_t end = emitted_codes_ + 1 + options_.decoding.lookahead_codes;
  while (static_cast<int64_t>(sampler_.codes().size()) < end) sampler_.Next();
  const std::vector<int64_t>& codes = sampler_.codes();
  // Codes [begin, end) are decoded.
  const int64_t begin =
      std::max<int64_t>(0, end - options_.decoding.context_codes);
  torch::Tensor window =
      torch::tensor(
          std::vector<int64_t>(codes.begin() + begin, codes.begin() + end),
          torch::kLong)
          .unsqueeze(0);
  torch::Tensor frames = tokenizer_.model->Decode(window)[0];  // [T, C]
  const int per_token = frames_per_token();
  torch::Tensor emitted =
      (frames.narrow(0, (emitted_codes_ - begin) * per_token, per_token) *
           tokenizer_.std +
       tokenizer_.mean)
          .contiguous();
  rows->insert(rows->end(), emitted.data_ptr<float>(),
               emitted.data_ptr<float>() + emitted.numel());
  ++emitted_codes_;
}

}  // namespace m2d
