// detect: people's 2D keypoints from images and video — a TF.js graph-model
// interpreter on LibTorch, MoveNet on it, and a tracker that keeps one
// person across frames.
#ifndef MIMIC2D_DETECT_MOVENET_H_
#define MIMIC2D_DETECT_MOVENET_H_

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "media/image.h"
#include "motion/clip2d.h"

namespace m2d {

enum class MoveNetModel {
  kLightning,  // single pose, 192x192 input: fast
  kThunder,    // single pose, 256x256 input: more accurate
};

// An axis-aligned box in image pixels.
struct Box {
  double x0_px = 0, y0_px = 0, x1_px = 0, y1_px = 0;
  double width_px() const { return x1_px - x0_px; }
  double height_px() const { return y1_px - y0_px; }
  double area_px2() const {
    return width_px() > 0 && height_px() > 0 ? width_px() * height_px() : 0.0;
  }
};

// Intersection over union of two boxes (0 when disjoint or empty).
double BoxIou(const Box& a, const Box& b);

// One person: COCO-17 keypoints in image pixels with MoveNet's scores as
// confidences, the person's box and score.
struct DetectedPerson {
  std::array<Keypoint2D, 17> keypoints;
  Box box;
  double score = 0.0;  // single pose: mean keypoint score
};

// The box around the keypoints scoring at least `min_score` (empty Box
// when fewer than 2 do).
Box KeypointBox(const DetectedPerson& person, double min_score);

// LibTorch's intra-op threads for detection (one is best when another
// process competes for the cores: two then collapse; docs/video.md).
void SetDetectionThreads(int threads);

// The folder with the MoveNet files: $MIMIC2D_MODELS when set, else
// assets/models/movenet of the source tree (setup.sh fills it).
std::string DefaultMoveNetFolder();

// MoveNet on LibTorch (the TF.js graph models of assets/models/README.md).
class MoveNet {
 public:
  // Loads the single-pose `model` and MultiPose from `folder`; InputError
  // naming a missing or damaged file.
  MoveNet(const std::string& folder, MoveNetModel model);
  ~MoveNet();
  MoveNet(MoveNet&&) noexcept;

  // Single pose in a square region of `image` (centre, side in px; parts
  // outside the image are black), resized to the model's input.
  DetectedPerson DetectInRegion(const RgbImage& image, double centre_x_px,
                                double centre_y_px, double side_px) const;

  // MultiPose on the whole image, resized so that its longer side is
  // `long_side_px` (both sides rounded to multiples of 32): up to 6 people
  // with score >= min_score, best first.
  std::vector<DetectedPerson> DetectPeople(const RgbImage& image,
                                           int long_side_px = 512,
                                           double min_score = 0.2) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace m2d

#endif  // MIMIC2D_DETECT_MOVENET_H_
