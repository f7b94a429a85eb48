#include "eval/metrics.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

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

double YawAlignedRootRelativeError(const KeypointFrames& simulated,
                                   const KeypointFrames& truth,
                                   const KeypointLayout& layout,
                                   double* yaw_rad) {
  // Outline: root-relative points of both; the yaw maximizing
  // sum b . R(yaw) a over x, y (atan2 of the cross and dot sums); the mean
  // distance after rotating the simulated points by it.
  const size_t num_frames = std::min(simulated.size(), truth.size());
  KeypointFrames relative_sim(num_frames), relative_true(num_frames);
  double dot = 0.0, cross = 0.0;
  for (size_t t = 0; t < num_frames; ++t) {
    const Eigen::Vector3d sim_root = Root(simulated[t], layout);
    const Eigen::Vector3d true_root = Root(truth[t], layout);
    for (size_t j = 0; j < simulated[t].size(); ++j) {
      const Eigen::Vector3d a = simulated[t][j] - sim_root;
      const Eigen::Vector3d b = truth[t][j] - true_root;
      dot += a.x() * b.x() + a.y() * b.y();
      cross += a.x() * b.y() - a.y() * b.x();
      relative_sim[t].push_back(a);
      relative_true[t].push_back(b);
    }
  }
  const double yaw = std::atan2(cross, dot);
  if (yaw_rad != nullptr) *yaw_rad = yaw;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (std::vector<Eigen::Vector3d>& frame : relative_sim) {
    for (Eigen::Vector3d& point : frame) point = rotation * point;
  }
  return MeanPositionError(relative_sim, relative_true);
}

double YawAlignedObjectError(
    const KeypointFrames& simulated,
    const std::vector<Eigen::Vector3d>& simulated_object,
    const KeypointFrames& truth,
    const std::vector<Eigen::Vector3d>& true_object,
    const KeypointLayout& layout, double yaw_rad) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const size_t num_frames =
      std::min({simulated.size(), truth.size(), simulated_object.size(),
                true_object.size()});
  if (num_frames == 0) return 0.0;
  double sum = 0.0;
  for (size_t t = 0; t < num_frames; ++t) {
    const Eigen::Vector3d ours =
        rotation * (simulated_object[t] - Root(simulated[t], layout));
    const Eigen::Vector3d theirs = true_object[t] - Root(truth[t], layout);
    sum += (ours - theirs).norm();
  }
  return sum / num_frames;
}

std::vector<double> ProcrustesAlignedErrorPerKeypoint(
    const KeypointFrames& simulated, const KeypointFrames& truth) {
  const size_t num_frames = std::min(simulated.size(), truth.size());
  if (num_frames == 0) return {};
  const long num_points = static_cast<long>(simulated[0].size());
  std::vector<double> sums(num_points, 0.0);
  for (size_t t = 0; t < num_frames; ++t) {
    Eigen::Matrix3Xd from(3, num_points), to(3, num_points);
    for (long j = 0; j < num_points; ++j) {
      from.col(j) = simulated[t][j];
      to.col(j) = truth[t][j];
    }
    const Eigen::Matrix4d transform = Eigen::umeyama(from, to, true);
    const Eigen::Matrix3Xd aligned =
        (transform.topLeftCorner<3, 3>() * from).colwise() +
        transform.topRightCorner<3, 1>();
    const Eigen::RowVectorXd distances = (aligned - to).colwise().norm();
    for (long j = 0; j < num_points; ++j) sums[j] += distances[j];
  }
  for (double& sum : sums) sum /= static_cast<double>(num_frames);
  return sums;
}

double ProcrustesAlignedError(const KeypointFrames& simulated,
                              const KeypointFrames& truth) {
  // Every frame holds every keypoint, so the mean of the per-keypoint means
  // is the mean over all of them.
  const std::vector<double> per_keypoint =
      ProcrustesAlignedErrorPerKeypoint(simulated, truth);
  if (per_keypoint.empty()) return 0.0;
  double sum = 0.0;
  for (double error : per_keypoint) sum += error;
  return sum / static_cast<double>(per_keypoint.size());
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

FeatureGaussian FitFeatureGaussian(const Eigen::MatrixXd& features) {
  FeatureGaussian gaussian;
  gaussian.count = static_cast<int>(features.rows());
  gaussian.mean = features.colwise().mean().transpose();
  const Eigen::MatrixXd centred =
      features.rowwise() - gaussian.mean.transpose();
  gaussian.covariance =
      centred.transpose() * centred /
      std::max<double>(1.0, static_cast<double>(features.rows()));
  return gaussian;
}

namespace {

// The symmetric square root of a symmetric positive semi-definite matrix.
Eigen::MatrixXd SymmetricSqrt(const Eigen::MatrixXd& matrix) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(matrix);
  const Eigen::VectorXd roots = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return solver.eigenvectors() * roots.asDiagonal() *
         solver.eigenvectors().transpose();
}

}  // namespace

double FrechetDistance(const FeatureGaussian& a, const FeatureGaussian& b) {
  // Tr((Σa Σb)^½) = Tr((Σa^½ Σb Σa^½)^½): the inner matrix is symmetric
  // positive semi-definite, so its root is real.
  const Eigen::MatrixXd root_a = SymmetricSqrt(a.covariance);
  const Eigen::MatrixXd inner = root_a * b.covariance * root_a;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      0.5 * (inner + inner.transpose()));
  const double cross_trace =
      solver.eigenvalues().cwiseMax(0.0).cwiseSqrt().sum();
  return (a.mean - b.mean).squaredNorm() + a.covariance.trace() +
         b.covariance.trace() - 2.0 * cross_trace;
}

double MeanPairDistance(const Eigen::MatrixXd& features, int pairs,
                        uint64_t seed) {
  const int rows = static_cast<int>(features.rows());
  if (rows < 2 || pairs <= 0) return 0.0;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, rows - 1);
  double sum = 0.0;
  for (int p = 0; p < pairs; ++p) {
    const int i = pick(rng);
    int j = pick(rng);
    while (j == i) j = pick(rng);
    sum += (features.row(i) - features.row(j)).norm();
  }
  return sum / pairs;
}

namespace {

// Squared distances between every row of `a` and every row of `b` (as
// |a|^2 + |b|^2 - 2 a.b, floored at 0 against round-off), in blocks of
// `a`'s rows, handed to `visit(first_row, block)`: a full matrix of two
// 12k-row sets would take a gigabyte.
template <typename Visit>
void ForEachDistanceBlock(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                          Visit visit) {
  constexpr int kBlockRows = 512;
  const Eigen::VectorXd b_norms = b.rowwise().squaredNorm();
  for (int first = 0; first < a.rows(); first += kBlockRows) {
    const int rows = std::min<int>(kBlockRows, a.rows() - first);
    const Eigen::MatrixXd block_a = a.middleRows(first, rows);
    Eigen::MatrixXd squared = -2.0 * block_a * b.transpose();
    squared.colwise() += block_a.rowwise().squaredNorm();
    squared.rowwise() += b_norms.transpose();
    visit(first, squared.cwiseMax(0.0));
  }
}

}  // namespace

Eigen::VectorXd KthNeighbourDistances(const Eigen::MatrixXd& rows, int k) {
  Eigen::VectorXd radii = Eigen::VectorXd::Constant(
      rows.rows(), std::numeric_limits<double>::infinity());
  if (k < 1 || rows.rows() <= k) return radii;
  std::vector<double> row_distances(rows.rows());
  ForEachDistanceBlock(
      rows, rows, [&](int first, const Eigen::MatrixXd& block) {
        for (int r = 0; r < block.rows(); ++r) {
          for (int c = 0; c < block.cols(); ++c) row_distances[c] = block(r, c);
          // Itself (distance 0) is the nearest: the k-th other is element k.
          std::nth_element(row_distances.begin(), row_distances.begin() + k,
                           row_distances.end());
          radii(first + r) = std::sqrt(row_distances[k]);
        }
      });
  return radii;
}

double ShareWithinRadii(const Eigen::MatrixXd& samples,
                        const Eigen::MatrixXd& set,
                        const Eigen::VectorXd& radii) {
  if (samples.rows() == 0) return 0.0;
  const Eigen::RowVectorXd squared_radii =
      radii.cwiseProduct(radii).transpose();
  int within = 0;
  ForEachDistanceBlock(samples, set, [&](int, const Eigen::MatrixXd& block) {
    for (int r = 0; r < block.rows(); ++r)
      within += ((block.row(r) - squared_radii).array() <= 0.0).any();
  });
  return static_cast<double>(within) / samples.rows();
}

PrecisionRecall ManifoldPrecisionRecall(const Eigen::MatrixXd& real,
                                        const Eigen::MatrixXd& generated,
                                        int k) {
  PrecisionRecall result;
  result.precision =
      ShareWithinRadii(generated, real, KthNeighbourDistances(real, k));
  result.recall =
      ShareWithinRadii(real, generated, KthNeighbourDistances(generated, k));
  return result;
}

}  // namespace m2d
