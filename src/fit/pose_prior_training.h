// fit: learning the pose prior (fit/pose_prior.h) from motion capture: the
// character's hinge angles over every frame of a set of motions, and a
// Gaussian mixture fitted to them by expectation-maximization (OpenCV's
// cv::ml::EM). Offline: `mimic2d prior`; the fit only reads the result.
#ifndef MIMIC2D_FIT_POSE_PRIOR_TRAINING_H_
#define MIMIC2D_FIT_POSE_PRIOR_TRAINING_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fit/pose_prior.h"
#include "motion/motion3d.h"

namespace m2d {

class Character;

struct PoseMixtureTrainingOptions {
  int num_components = 8;  // SMPLify's prior over CMU has 8
  // Added to every variance (as a standard deviation, rad): a hinge the data
  // barely moves (the neck, while walking) stays movable at the fit's weight
  // instead of becoming a rigid joint.
  double min_std_rad = 0.1;
  int frame_stride = 2;  // every n-th frame: neighbours add little but time
  int max_iterations = 300;
  uint64_t seed = 1;  // EM's k-means++ start

  void Validate() const;  // throws ConfigError
};

// The hinge angles (rad, action order, clamped to the hinges' ranges as the
// fit holds them) of every `stride`-th frame of `motion`, a motion of
// `character`'s skeleton. InputError naming `source` otherwise.
std::vector<Eigen::VectorXd> HingeAnglesOfMotion(const Character& character,
                                                 const Motion3D& motion,
                                                 int stride,
                                                 const std::string& source);

struct PoseMixtureTrainingSummary {
  int num_samples = 0;
  double mean_log_likelihood = 0.0;  // per sample, under EM's model
  double mean_cost = 0.0;            // PoseMixture::Cost, per sample
  std::string BriefReport() const;
};

// Fits the mixture to `samples` (each of the character's hinges);
// InputError naming `source` for too few samples (fewer than 2 (hinges +
// 1) per component) or a non-finite angle.
PoseMixture TrainPoseMixture(const Character& character,
                             const std::vector<Eigen::VectorXd>& samples,
                             const PoseMixtureTrainingOptions& options,
                             const std::string& source,
                             PoseMixtureTrainingSummary* summary = nullptr);

// The character's hinge names in action order (the mixture's dimensions).
std::vector<std::string> HingeNames(const Character& character);

}  // namespace m2d

#endif  // MIMIC2D_FIT_POSE_PRIOR_TRAINING_H_
