#include "gen/generated_stream.h"

#include <filesystem>

#include "common/error.h"
#include "gen/gen_checkpoint.h"
#include "gen/gen_trainer.h"
#include "gen/motion_dataset.h"
#include "gen/motion_stream.h"
#include "motion/canonical.h"

namespace m2d {

GeneratedStream::GeneratedStream(const std::string& run_dir,
                                 const GeneratedStreamOptions& options)
    : root_px_(options.first_root_px), scale_px_(options.first_scale_px) {
  options.sampling.Validate();
  if (!(options.first_scale_px > 0)) {
    throw ConfigError("generated stream: the first scale must be positive");
  }
  const std::filesystem::path run(run_dir);
  LoadedTokenizer tokenizer = LoadTokenizer((run / kTokenizerFile).string());
  format_.layout = &Coco17Layout();
  format_.fps = tokenizer.config.data.fps;
  format_.image_width_px = options.image_width_px;
  format_.image_height_px = options.image_height_px;
  stream_ = std::make_unique<MotionStream>(
      std::move(tokenizer), LoadPrior((run / kPriorFile).string()),
      MotionStreamOptions{options.sampling, options.decoding, options.seed});
}

GeneratedStream::~GeneratedStream() = default;

bool GeneratedStream::Next(std::vector<Keypoint2D>* keypoints) {
  // Outline: draw the next code's frames when those decoded are used up;
  // then one frame from its local pose and steps, the running root and
  // scale advanced as FromCanonical does.
  const KeypointLayout& layout = *format_.layout;
  const int num_keypoints = layout.num_keypoints();
  const size_t frame_size = CanonicalFrameSize(layout);
  if (next_row_ * frame_size >= rows_.size()) {
    rows_.clear();
    next_row_ = 0;
    stream_->Next(&rows_);
  }
  const float* row = rows_.data() + next_row_++ * frame_size;
  std::vector<Keypoint2D> local(num_keypoints);
  for (int j = 0; j < num_keypoints; ++j)
    local[j] = {row[2 * j], row[2 * j + 1], 1.0};
  keypoints->resize(num_keypoints);
  CanonicalFrameToAbsolute(
      local.data(), num_keypoints,
      Eigen::Vector2d(row[2 * num_keypoints], row[2 * num_keypoints + 1]),
      row[2 * num_keypoints + 2], &root_px_, &scale_px_, keypoints->data());
  return true;
}

}  // namespace m2d
