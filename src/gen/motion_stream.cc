#include "gen/motion_stream.h"

#include <algorithm>

#include "common/error.h"

namespace m2d {

MotionStream::MotionStream(LoadedTokenizer tokenizer, LoadedPrior prior,
                           const GenerationOptions& options)
    : tokenizer_(std::move(tokenizer)),
      sampler_(std::in_place, prior.model, options.sampling, options.seed,
               options.view),
      options_(options),
      anchor_(options.placement_return_s, tokenizer_.config.data.fps) {
  if (prior.model->num_codes() != tokenizer_.model->num_codes()) {
    throw ConfigError("the prior predicts " +
                      std::to_string(prior.model->num_codes()) +
                      " codes but the tokenizer has " +
                      std::to_string(tokenizer_.model->num_codes()) +
                      ": they come from different runs");
  }
  CheckDecoding();
}

MotionStream::MotionStream(LoadedTokenizer tokenizer,
                           std::vector<int64_t> codes,
                           const GenerationOptions& options)
    : tokenizer_(std::move(tokenizer)),
      replayed_codes_(std::move(codes)),
      options_(options),
      anchor_(options.placement_return_s, tokenizer_.config.data.fps) {
  for (int64_t code : replayed_codes_) {
    if (code < 0 || code >= tokenizer_.model->num_codes())
      throw ConfigError("stream: replayed code " + std::to_string(code) +
                        " is not one of the tokenizer's " +
                        std::to_string(tokenizer_.model->num_codes()));
  }
  CheckDecoding();
}

void MotionStream::CheckDecoding() {
  const StreamDecoding& decoding = options_.decoding;
  if (decoding.lookahead_codes < 0 || decoding.emit_codes < 1 ||
      decoding.context_codes < decoding.lookahead_codes + decoding.emit_codes)
    throw ConfigError(
        "stream: lookahead_codes must be >= 0, emit_codes >= 1 and "
        "context_codes >= lookahead_codes + emit_codes");
  tokenizer_.model->eval();
}

bool MotionStream::HaveCodes(int64_t end) {
  if (!sampler_) return static_cast<int64_t>(replayed_codes_.size()) >= end;
  while (static_cast<int64_t>(sampler_->codes().size()) < end) sampler_->Next();
  return true;
}

int64_t MotionStream::frames_available() const {
  if (sampler_) return 0;
  // Whole decodings of emit_codes codes, each needing its lookahead after
  // it, then the frames of the current decoding not yet emitted.
  const StreamDecoding& decoding = options_.decoding;
  const int64_t usable = static_cast<int64_t>(replayed_codes_.size()) -
                         decoding.lookahead_codes - emitted_codes_;
  const int64_t pending = static_cast<int64_t>(decoded_.size() / frame_size()) -
                          static_cast<int64_t>(next_decoded_row_);
  const int64_t whole =
      std::max<int64_t>(0, usable - pending / frames_per_token()) /
      decoding.emit_codes * decoding.emit_codes;
  return pending + whole * frames_per_token();
}

void MotionStream::Next(std::vector<float>* rows) {
  // Inference only: no autograd bookkeeping on any tensor made here.
  c10::InferenceMode inference;
  // Outline: when nothing decoded is left, draw codes until the lookahead
  // after the next emit_codes codes exists, decode the latest codes, keep
  // the frames of those emit_codes (their first ones blended in from the
  // previous decoding's lookahead) and this decoding's lookahead frames;
  // then emit one code's frames.
  const int per_token = frames_per_token();
  const size_t row_size = static_cast<size_t>(frame_size());
  if (next_decoded_row_ * row_size >= decoded_.size()) {
    const StreamDecoding& decoding = options_.decoding;
    const int64_t end =
        emitted_codes_ + decoding.emit_codes + decoding.lookahead_codes;
    if (!HaveCodes(end))
      throw ConfigError("stream: the replayed codes end before code " +
                        std::to_string(end));
    const std::vector<int64_t>& codes = this->codes();
    // Codes [begin, end) are decoded.
    const int64_t begin = std::max<int64_t>(0, end - decoding.context_codes);
    torch::Tensor window =
        torch::tensor(
            std::vector<int64_t>(codes.begin() + begin, codes.begin() + end),
            torch::kLong)
            .unsqueeze(0);
    torch::Tensor frames = tokenizer_.model->Decode(window)[0];  // [T, C]
    frames = (frames * tokenizer_.std + tokenizer_.mean).contiguous();
    const float* first_kept = frames.data_ptr<float>() +
                              (emitted_codes_ - begin) * per_token * row_size;
    const size_t kept_size = decoding.emit_codes * per_token * row_size;
    decoded_.assign(first_kept, first_kept + kept_size);
    if (decoding.blend_seams) {
      const size_t overlap = std::min(lookahead_.size(), decoded_.size());
      const size_t overlap_rows = overlap / row_size;
      for (size_t i = 0; i < overlap; ++i) {
        const float weight = static_cast<float>(i / row_size + 1) /
                             static_cast<float>(overlap_rows + 1);
        decoded_[i] = (1.0f - weight) * lookahead_[i] + weight * decoded_[i];
      }
      const float* first_lookahead = first_kept + kept_size;
      lookahead_.assign(
          first_lookahead,
          first_lookahead + decoding.lookahead_codes * per_token * row_size);
    }
    anchor_.Apply(decoded_.data(), static_cast<int>(decoded_.size() / row_size),
                  static_cast<int>(row_size));
    next_decoded_row_ = 0;
  }
  const auto first = decoded_.begin() + next_decoded_row_ * row_size;
  rows->insert(rows->end(), first, first + per_token * row_size);
  next_decoded_row_ += per_token;
  ++emitted_codes_;
}

}  // namespace m2d
