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
  options.generation.sampling.Validate();
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
      options.generation);
}

GeneratedStream::~GeneratedStream() = default;

bool GeneratedStream::Next(std::vector<Keypoint2D>* keypoints) {
  // Outline: draw the next code's frames when those decoded are used up;
  // then one frame as a one-frame clip placed at the running root and scale
  // (CanonicalFromFeatures applies its steps on top of them, as
  // FromCanonical does for a clip's later frames), which become its own.
  const KeypointLayout& layout = *format_.layout;
  const size_t frame_size = CanonicalFrameSize(layout);
  if (next_row_ * frame_size >= rows_.size()) {
    rows_.clear();
    next_row_ = 0;
    stream_->Next(&rows_);
  }
  const CanonicalClip frame =
      CanonicalFromFeatures(rows_.data() + next_row_++ * frame_size, 1, layout,
                            format_.fps, root_px_, scale_px_);
  root_px_ = frame.first_root_px;
  scale_px_ = frame.first_scale_px;
  const Clip2D absolute = FromCanonical(frame);
  const Keypoint2D* points = absolute.keypoints.frame(0);
  keypoints->assign(points, points + layout.num_keypoints());
  return true;
}

}  // namespace m2d
