// gen: a generator's motion as a reference stream for the tracker
// (env/reference_stream.h): the run's prior and tokenizer draw and decode
// as frames are asked for, and each frame of X^can becomes absolute 2D
// from a placement (where the first frame's root is, and its scale).
// LibTorch stays in the .cc.
#ifndef MIMIC2D_GEN_GENERATED_STREAM_H_
#define MIMIC2D_GEN_GENERATED_STREAM_H_

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "env/reference_stream.h"
#include "gen/gen_config.h"

namespace m2d {

class MotionStream;

struct GeneratedStreamOptions {
  GenerationOptions generation;
  // The first frame's root and scale (px), as CanonicalFromFeatures takes
  // them: the first frame's own steps apply on top.
  Eigen::Vector2d first_root_px = Eigen::Vector2d(960, 540);
  double first_scale_px = 100.0;
  int image_width_px = 1920;
  int image_height_px = 1080;
};

// Endless: Next() never returns false. InputError naming the run's files
// when they are not a generator's checkpoints.
class GeneratedStream : public ReferenceStream {
 public:
  GeneratedStream(const std::string& run_dir,
                  const GeneratedStreamOptions& options);
  ~GeneratedStream() override;

  const Clip2D& format() const override { return format_; }
  bool Next(std::vector<Keypoint2D>* keypoints) override;

 private:
  std::unique_ptr<MotionStream> stream_;
  Clip2D format_;
  std::vector<float> rows_;  // X^can frames decoded, not yet handed out
  size_t next_row_ = 0;
  Eigen::Vector2d root_px_;  // the last frame's root and scale
  double scale_px_;
};

}  // namespace m2d

#endif  // MIMIC2D_GEN_GENERATED_STREAM_H_
