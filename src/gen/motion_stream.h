// gen: endless generation — the prior draws a code at a time and the
// tokenizer's decoder turns the latest codes into frames of X^can, streamed
// as they are made.
#ifndef MIMIC2D_GEN_MOTION_STREAM_H_
#define MIMIC2D_GEN_MOTION_STREAM_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "gen/gen_checkpoint.h"
#include "gen/gpt.h"

namespace m2d {

// Each Next() emits one code's frames. Frames are decoded for
// `decoding.emit_codes` codes at a time, once `decoding.lookahead_codes`
// codes after them exist, so that the decoder does not work at the
// window's open edge; later calls emit the frames already decoded. The
// decoded frames' placement steps are held by a PlacementAnchor
// (options.placement_return_s).
class MotionStream {
 public:
  MotionStream(LoadedTokenizer tokenizer, LoadedPrior prior,
               const GenerationOptions& options);
  // Replays given codes (e.g. a real sequence's, TokenizeDataset) through
  // the same decoding instead of drawing them: what the streaming decoder
  // alone does to real motion. Next() throws ConfigError once the codes
  // left cannot fill a decoding; frames_available() says how many can be
  // emitted. options.sampling, seed and view are not used.
  MotionStream(LoadedTokenizer tokenizer, std::vector<int64_t> codes,
               const GenerationOptions& options);

  // Appends frames_per_token() rows of X^can (not normalized; rows of
  // CanonicalFeatures) to `rows`.
  void Next(std::vector<float>* rows);

  int frames_per_token() const { return tokenizer_.model->frames_per_token(); }
  int frame_size() const { return tokenizer_.model->frame_size(); }
  const std::vector<int64_t>& codes() const {
    return sampler_ ? sampler_->codes() : replayed_codes_;
  }
  // Replaying: the frames Next() can still emit in all (0 when drawing).
  int64_t frames_available() const;

 private:
  void CheckDecoding();  // ConfigError for bad decoding options; eval mode
  // The codes up to `end` exist: drawn, or, replaying, there.
  bool HaveCodes(int64_t end);

  LoadedTokenizer tokenizer_;
  std::optional<TokenSampler> sampler_;  // empty: replaying
  std::vector<int64_t> replayed_codes_;
  GenerationOptions options_;
  PlacementAnchor anchor_;  // holds the emitted rows' placement
  int64_t emitted_codes_ = 0;
  std::vector<float> decoded_;  // frames decoded, not yet emitted
  // The last decoding's lookahead frames (not normalized, before the
  // anchor): what the next decoding's first frames blend in from.
  std::vector<float> lookahead_;
  size_t next_decoded_row_ = 0;  // in decoded_, in rows
};

}  // namespace m2d

#endif  // MIMIC2D_GEN_MOTION_STREAM_H_
