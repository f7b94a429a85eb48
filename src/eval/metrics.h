// eval: the paper's metrics (Succ, E2D, EO2D, E3D, Jitter) as pure
// functions, and the evaluation of a policy over reference bundles.
#ifndef MIMIC2D_EVAL_METRICS_H_
#define MIMIC2D_EVAL_METRICS_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "motion/layout.h"

namespace m2d {

using KeypointFrames = std::vector<std::vector<Eigen::Vector3d>>;  // T x J

// Mean over frames and keypoints of |x_sim - x_true| (metres).
double MeanPositionError(const KeypointFrames& simulated,
                         const KeypointFrames& truth);

// The same after subtracting each frame's root (mean of the layout's root
// keypoints) from both: pose error independent of global drift (metres).
double RootRelativePositionError(const KeypointFrames& simulated,
                                 const KeypointFrames& truth,
                                 const KeypointLayout& layout);

// For worlds whose headings differ (a fit's world frame against the
// truth's): the root-relative error after the single rotation about z that
// best aligns the simulated root-relative keypoints to the truth's over all
// frames (closed-form 2D Procrustes on x, y; metres). `yaw_rad`, when given,
// receives that rotation.
double YawAlignedRootRelativeError(const KeypointFrames& simulated,
                                   const KeypointFrames& truth,
                                   const KeypointLayout& layout,
                                   double* yaw_rad = nullptr);

// An object's error in worlds whose headings differ: per frame, its offset
// from the character's root (mean of the layout's root keypoints) turned by
// `yaw_rad` (YawAlignedRootRelativeError's rotation of the same worlds)
// against the truth's offset; the mean distance (metres).
double YawAlignedObjectError(
    const KeypointFrames& simulated,
    const std::vector<Eigen::Vector3d>& simulated_object,
    const KeypointFrames& truth,
    const std::vector<Eigen::Vector3d>& true_object,
    const KeypointLayout& layout, double yaw_rad);

// PA-MPJPE: per frame, the similarity transform (rotation, translation,
// scale; Umeyama) that best maps the simulated keypoints onto the truth's,
// then the mean distance (metres): pose error alone.
double ProcrustesAlignedError(const KeypointFrames& simulated,
                              const KeypointFrames& truth);
// The same alignment, the mean distance per keypoint (metres, one entry per
// keypoint of the first frame): which keypoints the pose error sits in (a
// limb fitted in its depth-mirrored solution shows as one or two keypoints
// far above the rest).
std::vector<double> ProcrustesAlignedErrorPerKeypoint(
    const KeypointFrames& simulated, const KeypointFrames& truth);

// Jitter: mean over frames and keypoints of the magnitude of the third
// time derivative of positions (finite differences at `fps`), in units of
// 10^3 m/s^3 as reported in the paper's tables. 0 for fewer than 4 frames.
double MeanJerk(const KeypointFrames& positions, double fps);

// A Gaussian fitted to feature vectors (one per row): what FID compares.
struct FeatureGaussian {
  Eigen::VectorXd mean;
  Eigen::MatrixXd covariance;  // maximum likelihood (divides by N)
  int count = 0;
};
FeatureGaussian FitFeatureGaussian(const Eigen::MatrixXd& features);

// The Fréchet distance between two Gaussians, FID when the features come
// from a motion encoder: |μa − μb|² + Tr(Σa + Σb − 2 (Σa^½ Σb Σa^½)^½).
// The matrix square roots come from symmetric eigendecompositions (small
// negative eigenvalues of round-off clamped to 0).
double FrechetDistance(const FeatureGaussian& a, const FeatureGaussian& b);

// Diversity: the mean distance between `pairs` random pairs of rows
// (distinct rows, drawn with `seed`); 0 with fewer than 2 rows.
double MeanPairDistance(const Eigen::MatrixXd& features, int pairs,
                        uint64_t seed);

// Improved precision and recall (Kynkaanniemi et al., NeurIPS 2019): a
// sample lies on a set's manifold when it is within some member's distance
// to that member's k-th nearest neighbour in the set. Precision: the share
// of generated rows on the real manifold (are they like real ones?);
// recall: the share of real rows on the generated manifold (is every kind
// of real one generated?). FID mixes the two; a generator that repeats a
// few real motions well has high precision and low recall.
struct PrecisionRecall {
  double precision = 0.0;
  double recall = 0.0;
};
// Each row's Euclidean distance to its k-th nearest other row (k >= 1;
// infinity when the set has no k other rows).
Eigen::VectorXd KthNeighbourDistances(const Eigen::MatrixXd& rows, int k);
// The share of `samples` rows within `radii`(i) of some row i of `set`.
double ShareWithinRadii(const Eigen::MatrixXd& samples,
                        const Eigen::MatrixXd& set,
                        const Eigen::VectorXd& radii);
PrecisionRecall ManifoldPrecisionRecall(const Eigen::MatrixXd& real,
                                        const Eigen::MatrixXd& generated,
                                        int k);

}  // namespace m2d

#endif  // MIMIC2D_EVAL_METRICS_H_
