#include "eval/metrics.h"

namespace m2d {
namespace {

Eigen::Vector3d Root(const std::vector<Eigen::Vector3d>& frame,
                     const KeypointLayout& layout) {
  Eigen::Vector3d root = Eigen::Vector3d::Zero();
  for (int index : layout.root_keypoints) root += frame[index];
  return root / static_cast<double>(layout.root_keypoints.size());
}

}  // namespace

double MeanPositionError(const KeypointFrames& simulated,
                         const KeypointFrames& truth) {
  double sum = 0.0;
  long count = 0;
  for (size_t t = 0; t < simulated.size() && t < truth.size(); ++t) {
    for (size_t j = 0; j < simulated[t].size(); ++j, ++count) {
      sum += (simulated[t][j] - truth[t][j]).norm();
    }
  }
  return count ? sum / count : 0.0;
}

double RootRelativePositionError(const KeypointFrames& simulated,
                                 const KeypointFrames& truth,
                                 const KeypointLayout& layout) {
  double sum = 0.0;
  long count = 0;
  for (size_t t = 0; t < simulated.size() && t < truth.size(); ++t) {
    Eigen::Vector3d sim_root = Root(simulated[t], layout),
                    true_root = Root(truth[t], layout);
    for (size_t j = 0; j < simulated[t].size(); ++j, ++count) {
      sum += ((simulated[t][j] - sim_root) - (truth[t][j] - true_root)).norm();
    }
  }
  return count ? sum / count : 0.0;
}

double MeanJerk(const KeypointFrames& positions, double fps) {
  if (positions.size() < 4) return 0.0;
  const double fps3 = fps * fps * fps;
  double sum = 0.0;
  long count = 0;
  for (size_t t = 0; t + 3 < positions.size(); ++t) {
    for (size_t j = 0; j < positions[t].size(); ++j, ++count) {
      Eigen::Vector3d jerk = positions[t + 3][j] - 3.0 * positions[t + 2][j] +
                             3.0 * positions[t + 1][j] - positions[t][j];
      sum += jerk.norm() * fps3;
    }
  }
  return sum / count / 1000.0;
}

}  // namespace m2d
