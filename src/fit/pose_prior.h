// fit: a learned pose prior, a Gaussian mixture over the character's hinge
// angles (SMPLify's MaxMixturePrior on our own skeleton). Learned once from
// motion capture (`mimic2d prior`, fit/pose_prior_training.h); the fit
// uses it in place of the pull toward the rest pose, so that of a limb's
// depth-mirrored twins the one people actually do wins. docs/fit.md.
#ifndef MIMIC2D_FIT_POSE_PRIOR_H_
#define MIMIC2D_FIT_POSE_PRIOR_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

namespace m2d {

// p(a) = sum_k w_k N(a; mu_k, Sigma_k) over the hinge angles a (rad, in the
// character's action order). As SMPLify, the fit uses the best component's
// negative log-likelihood, min_k [ 1/2 |U_k (a - mu_k)|^2 + c_k ], with
// U_k^T U_k = Sigma_k^-1 and c_k = -log w_k + 1/2 log det Sigma_k, offset so
// that min_k c_k = 0 (the cost is 0 at the likeliest component's mean).
struct PoseMixture {
  std::string character;                 // the character it was learned for
  std::vector<std::string> hinge_names;  // the dimensions, in action order
  std::vector<double> weights;           // w_k, summing to 1
  std::vector<Eigen::VectorXd> means;    // mu_k (rad)
  std::vector<Eigen::MatrixXd> precision_factors;  // U_k, upper triangular
  std::vector<double> component_costs;             // c_k, min 0
  // Where it was learned from, for the record (files, frames).
  std::vector<std::string> sources;
  int num_training_frames = 0;

  int num_components() const { return static_cast<int>(weights.size()); }
  int num_hinges() const { return static_cast<int>(hinge_names.size()); }

  // Builds a mixture from weights, means and covariances (precision factors
  // and component costs derived here); ConfigError when they disagree in
  // size or a covariance is not positive definite.
  static PoseMixture FromCovariances(
      std::string character, std::vector<std::string> hinge_names,
      std::vector<double> weights, std::vector<Eigen::VectorXd> means,
      const std::vector<Eigen::MatrixXd>& covariances);

  // The component with the lowest cost at `hinges_rad` (num_hinges values).
  int BestComponent(const double* hinges_rad) const;
  // The mixture cost at `hinges_rad`: min over components (>= 0).
  double Cost(const double* hinges_rad) const;
  // The mixture of the marginal over `hinge_indices` (a limb's hinges): the
  // same weights, the means' and covariances' sub-blocks.
  PoseMixture Marginal(const std::vector<int>& hinge_indices) const;
  // Covariance of component k (from its precision factor).
  Eigen::MatrixXd Covariance(int k) const;
};

// JSON (docs/formats.md): reads and checks sizes, finiteness and
// triangularity; InputError naming `path`.
PoseMixture ReadPoseMixture(const std::string& path);
void WritePoseMixtureAtomic(const PoseMixture& mixture,
                            const std::string& path);

// InputError naming `source` unless `mixture` was learned for exactly these
// hinges (names and order), e.g. a prior of another character.
void CheckPoseMixtureHinges(const PoseMixture& mixture,
                            const std::vector<std::string>& hinge_names,
                            const std::string& source);

// The value of a number or of a Jet, without its derivatives.
inline double ScalarPart(double x) { return x; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& x) {
  return x.a;
}

// The prior's num_hinges() + 1 residuals at `angles` (doubles or Jets):
// weight x [U_k (a - mu_k); sqrt(2 c_k)], k the best component at the
// angles' values (held for the derivatives).
template <typename T>
void MixtureResiduals(const PoseMixture& mixture, double weight,
                      const T* angles, T* residuals) {
  const int dims = mixture.num_hinges();
  std::vector<double> values(dims);
  for (int i = 0; i < dims; ++i) values[i] = ScalarPart(angles[i]);
  const int k = mixture.BestComponent(values.data());
  const Eigen::MatrixXd& factor = mixture.precision_factors[k];
  for (int r = 0; r < dims; ++r) {
    T sum(0);
    for (int c = r; c < dims; ++c)
      sum += factor(r, c) * (angles[c] - T(mixture.means[k][c]));
    residuals[r] = T(weight) * sum;
  }
  residuals[dims] = T(weight * std::sqrt(2.0 * mixture.component_costs[k]));
}

// The fit's pose-prior term on one block of hinge angles (`mixture`'s
// dimensions): weight x [U_k (a - mu_k); sqrt(2 c_k)] for the best component
// k at the current angles, so that half its squared norm is weight^2 times
// the mixture cost. Analytic Jacobian weight x U_k (the component is held
// within an evaluation, as in SMPLify). `mixture` must outlive the cost.
class MixturePriorCost : public ceres::CostFunction {
 public:
  MixturePriorCost(const PoseMixture* mixture, double weight);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const PoseMixture* mixture_;
  double weight_;
};

}  // namespace m2d

#endif  // MIMIC2D_FIT_POSE_PRIOR_H_
