#include "fit/pose_prior.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.h"
#include "common/file_io.h"

namespace m2d {
namespace {

// U, upper triangular with U^T U = covariance^-1 (the precision's Cholesky
// factor), so |U (a - mu)|^2 is the Mahalanobis distance; and log det of the
// covariance.
Eigen::MatrixXd PrecisionFactor(const Eigen::MatrixXd& covariance,
                                double* log_det_covariance) {
  Eigen::LLT<Eigen::MatrixXd> covariance_llt(covariance);
  if (covariance_llt.info() != Eigen::Success)
    throw ConfigError("pose prior: a covariance is not positive definite");
  const Eigen::MatrixXd lower = covariance_llt.matrixL();
  *log_det_covariance = 2.0 * lower.diagonal().array().log().sum();
  const Eigen::MatrixXd precision = covariance_llt.solve(
      Eigen::MatrixXd::Identity(covariance.rows(), covariance.cols()));
  Eigen::LLT<Eigen::MatrixXd> precision_llt(precision);
  if (precision_llt.info() != Eigen::Success)
    throw ConfigError("pose prior: a precision is not positive definite");
  return precision_llt.matrixU();
}

double HalfMahalanobis(const PoseMixture& mixture, int k, const double* a) {
  const Eigen::Map<const Eigen::VectorXd> angles(a, mixture.num_hinges());
  const Eigen::VectorXd offset = angles - mixture.means[k];
  const Eigen::VectorXd whitened =
      mixture.precision_factors[k].triangularView<Eigen::Upper>() * offset;
  return 0.5 * whitened.squaredNorm();
}

}  // namespace

PoseMixture PoseMixture::FromCovariances(
    std::string character, std::vector<std::string> hinge_names,
    std::vector<double> weights, std::vector<Eigen::VectorXd> means,
    const std::vector<Eigen::MatrixXd>& covariances) {
  const int dims = static_cast<int>(hinge_names.size());
  const size_t count = weights.size();
  if (count == 0 || means.size() != count || covariances.size() != count)
    throw ConfigError(
        "pose prior: weights, means and covariances differ in count");
  PoseMixture mixture;
  mixture.character = std::move(character);
  mixture.hinge_names = std::move(hinge_names);
  double total = 0.0;
  for (double w : weights) {
    if (!(std::isfinite(w) && w > 0))
      throw ConfigError("pose prior: a component weight is not positive");
    total += w;
  }
  std::vector<double> log_dets(count);
  for (size_t k = 0; k < count; ++k) {
    if (means[k].size() != dims || covariances[k].rows() != dims ||
        covariances[k].cols() != dims) {
      throw ConfigError("pose prior: component " + std::to_string(k) +
                        " is not of " + std::to_string(dims) + " hinges");
    }
    mixture.weights.push_back(weights[k] / total);
    mixture.means.push_back(means[k]);
    mixture.precision_factors.push_back(
        PrecisionFactor(covariances[k], &log_dets[k]));
  }
  for (size_t k = 0; k < count; ++k) {
    mixture.component_costs.push_back(-std::log(mixture.weights[k]) +
                                      0.5 * log_dets[k]);
  }
  const double lowest = *std::min_element(mixture.component_costs.begin(),
                                          mixture.component_costs.end());
  for (double& c : mixture.component_costs) c -= lowest;
  return mixture;
}

int PoseMixture::BestComponent(const double* hinges_rad) const {
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int k = 0; k < num_components(); ++k) {
    const double cost =
        HalfMahalanobis(*this, k, hinges_rad) + component_costs[k];
    if (cost < best_cost) {
      best_cost = cost;
      best = k;
    }
  }
  return best;
}

double PoseMixture::Cost(const double* hinges_rad) const {
  const int k = BestComponent(hinges_rad);
  return HalfMahalanobis(*this, k, hinges_rad) + component_costs[k];
}

Eigen::MatrixXd PoseMixture::Covariance(int k) const {
  const Eigen::MatrixXd precision =
      precision_factors[k].transpose() * precision_factors[k];
  return precision.llt().solve(
      Eigen::MatrixXd::Identity(num_hinges(), num_hinges()));
}

PoseMixture PoseMixture::Marginal(const std::vector<int>& hinge_indices) const {
  const int dims = static_cast<int>(hinge_indices.size());
  std::vector<std::string> names;
  for (int h : hinge_indices) names.push_back(hinge_names.at(h));
  std::vector<Eigen::VectorXd> sub_means;
  std::vector<Eigen::MatrixXd> sub_covariances;
  for (int k = 0; k < num_components(); ++k) {
    const Eigen::MatrixXd covariance = Covariance(k);
    Eigen::VectorXd mean(dims);
    Eigen::MatrixXd sub(dims, dims);
    for (int i = 0; i < dims; ++i) {
      mean[i] = means[k][hinge_indices[i]];
      for (int j = 0; j < dims; ++j)
        sub(i, j) = covariance(hinge_indices[i], hinge_indices[j]);
    }
    sub_means.push_back(mean);
    sub_covariances.push_back(sub);
  }
  PoseMixture marginal = FromCovariances(character, names, weights,
                                         std::move(sub_means), sub_covariances);
  marginal.sources = sources;
  marginal.num_training_frames = num_training_frames;
  return marginal;
}

PoseMixture ReadPoseMixture(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  try {
    if (json.at("format").get<std::string>() != "mimic2d-pose-mixture")
      throw InputError(path,
                       "not a pose mixture (format is not "
                       "'mimic2d-pose-mixture')");
    std::vector<double> weights;
    std::vector<Eigen::VectorXd> means;
    std::vector<Eigen::MatrixXd> covariances;
    const auto names = json.at("hinges").get<std::vector<std::string>>();
    const int dims = static_cast<int>(names.size());
    for (const nlohmann::json& component : json.at("components")) {
      weights.push_back(component.at("weight").get<double>());
      const auto mean = component.at("mean_rad").get<std::vector<double>>();
      const auto covariance =
          component.at("covariance_rad2").get<std::vector<double>>();
      if (static_cast<int>(mean.size()) != dims ||
          static_cast<int>(covariance.size()) != dims * dims) {
        throw InputError(path, "component " +
                                   std::to_string(weights.size() - 1) +
                                   ": mean or covariance is not of " +
                                   std::to_string(dims) + " hinges");
      }
      for (double x : mean) {
        if (!std::isfinite(x)) throw InputError(path, "a mean is not finite");
      }
      for (double x : covariance) {
        if (!std::isfinite(x))
          throw InputError(path, "a covariance is not finite");
      }
      means.push_back(Eigen::Map<const Eigen::VectorXd>(mean.data(), dims));
      covariances.push_back(
          Eigen::Map<const Eigen::MatrixXd>(covariance.data(), dims, dims));
    }
    PoseMixture mixture = PoseMixture::FromCovariances(
        json.at("character").get<std::string>(), names, std::move(weights),
        std::move(means), covariances);
    if (json.contains("sources"))
      mixture.sources = json["sources"].get<std::vector<std::string>>();
    mixture.num_training_frames = json.value("training_frames", 0);
    return mixture;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, std::string("malformed pose mixture: ") + e.what());
  } catch (const ConfigError& e) {
    throw InputError(path, e.what());
  }
}

void WritePoseMixtureAtomic(const PoseMixture& mixture,
                            const std::string& path) {
  nlohmann::json json;
  json["format"] = "mimic2d-pose-mixture";
  json["character"] = mixture.character;
  json["hinges"] = mixture.hinge_names;
  json["sources"] = mixture.sources;
  json["training_frames"] = mixture.num_training_frames;
  json["components"] = nlohmann::json::array();
  for (int k = 0; k < mixture.num_components(); ++k) {
    const Eigen::MatrixXd covariance = mixture.Covariance(k);
    json["components"].push_back(
        {{"weight", mixture.weights[k]},
         {"mean_rad",
          std::vector<double>(mixture.means[k].data(),
                              mixture.means[k].data() + mixture.num_hinges())},
         {"covariance_rad2",
          std::vector<double>(covariance.data(),
                              covariance.data() + covariance.size())}});
  }
  WriteJsonFileAtomic(path, json, 1);
}

void CheckPoseMixtureHinges(const PoseMixture& mixture,
                            const std::vector<std::string>& hinge_names,
                            const std::string& source) {
  if (mixture.hinge_names != hinge_names) {
    throw InputError(source, "the pose prior was learned for character '" +
                                 mixture.character + "' with " +
                                 std::to_string(mixture.num_hinges()) +
                                 " hinges, which are not this character's " +
                                 std::to_string(hinge_names.size()) +
                                 " (names or order differ): learn it again "
                                 "with mimic2d prior");
  }
}

MixturePriorCost::MixturePriorCost(const PoseMixture* mixture, double weight)
    : mixture_(mixture), weight_(weight) {
  mutable_parameter_block_sizes()->push_back(mixture->num_hinges());
  set_num_residuals(mixture->num_hinges() + 1);
}

bool MixturePriorCost::Evaluate(double const* const* parameters,
                                double* residuals, double** jacobians) const {
  const int dims = mixture_->num_hinges();
  MixtureResiduals(*mixture_, weight_, parameters[0], residuals);
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    const Eigen::MatrixXd& factor =
        mixture_->precision_factors[mixture_->BestComponent(parameters[0])];
    Eigen::Map<
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        jacobian(jacobians[0], dims + 1, dims);
    jacobian.topRows(dims) =
        weight_ * factor.triangularView<Eigen::Upper>().toDenseMatrix();
    jacobian.row(dims).setZero();
  }
  return true;
}

}  // namespace m2d
