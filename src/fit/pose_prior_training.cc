#include "fit/pose_prior_training.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>
#include <sstream>

#include "common/error.h"
#include "sim/character.h"
#include "sim/pose_mapping.h"

namespace m2d {

void PoseMixtureTrainingOptions::Validate() const {
  if (num_components < 1 || num_components > 64)
    throw ConfigError("pose prior: num_components must be in [1, 64]");
  if (!(std::isfinite(min_std_rad) && min_std_rad >= 0))
    throw ConfigError("pose prior: min_std_rad must be >= 0");
  if (frame_stride < 1)
    throw ConfigError("pose prior: frame_stride must be >= 1");
  if (max_iterations < 1)
    throw ConfigError("pose prior: max_iterations must be >= 1");
}

std::vector<std::string> HingeNames(const Character& character) {
  std::vector<std::string> names;
  for (const ActuatedHinge& hinge : character.hinges()) {
    const char* name =
        mj_id2name(character.model(), mjOBJ_JOINT, hinge.joint_id);
    names.push_back(name != nullptr ? name
                                    : "joint" + std::to_string(hinge.joint_id));
  }
  return names;
}

std::vector<Eigen::VectorXd> HingeAnglesOfMotion(const Character& character,
                                                 const Motion3D& motion,
                                                 int stride,
                                                 const std::string& source) {
  if (motion.skeleton == nullptr ||
      motion.skeleton->name != character.skeleton().name) {
    throw InputError(source, "the motion is not of the character's skeleton '" +
                                 character.skeleton().name + "'");
  }
  std::vector<double> qpos(character.model()->nq, 0.0);
  std::vector<Eigen::VectorXd> samples;
  for (int t = 0; t < motion.num_frames(); t += std::max(stride, 1)) {
    PoseToQpos(character, motion.frames[t], qpos.data());
    Eigen::VectorXd angles(character.num_actions());
    for (int h = 0; h < character.num_actions(); ++h) {
      const ActuatedHinge& hinge = character.hinges()[h];
      angles[h] = std::clamp(qpos[hinge.qpos_address], hinge.range_low_rad,
                             hinge.range_high_rad);
    }
    if (!angles.allFinite()) {
      throw InputError(source, "frame " + std::to_string(t) +
                                   " has a non-finite joint angle");
    }
    samples.push_back(std::move(angles));
  }
  return samples;
}

std::string PoseMixtureTrainingSummary::BriefReport() const {
  std::ostringstream out;
  out << num_samples << " poses, mean log-likelihood " << mean_log_likelihood
      << ", mean prior cost " << mean_cost;
  return out.str();
}

PoseMixture TrainPoseMixture(const Character& character,
                             const std::vector<Eigen::VectorXd>& samples,
                             const PoseMixtureTrainingOptions& options,
                             const std::string& source,
                             PoseMixtureTrainingSummary* summary) {
  // Outline: check the samples, run EM (k-means++ start, full
  // covariances), widen each covariance by min_std_rad, build the mixture.
  options.Validate();
  const int dims = character.num_actions();
  // A full covariance is singular with fewer than dims + 1 poses; ask for
  // twice that per component (min_std_rad regularizes the rest).
  const int needed = 2 * options.num_components * (dims + 1);
  if (static_cast<int>(samples.size()) < needed) {
    throw InputError(source, std::to_string(samples.size()) +
                                 " poses are too few for " +
                                 std::to_string(options.num_components) +
                                 " components over " + std::to_string(dims) +
                                 " hinges (need " + std::to_string(needed) +
                                 "): add motions or lower --components");
  }
  cv::Mat data(static_cast<int>(samples.size()), dims, CV_64F);
  for (int i = 0; i < data.rows; ++i) {
    if (samples[i].size() != dims || !samples[i].allFinite()) {
      throw InputError(source, "pose " + std::to_string(i) + " is not " +
                                   std::to_string(dims) + " finite angles");
    }
    for (int d = 0; d < dims; ++d) data.at<double>(i, d) = samples[i][d];
  }
  cv::theRNG().state = options.seed;
  cv::Ptr<cv::ml::EM> em = cv::ml::EM::create();
  em->setClustersNumber(options.num_components);
  em->setCovarianceMatrixType(cv::ml::EM::COV_MAT_GENERIC);
  em->setTermCriteria(
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                       options.max_iterations, 1e-6));
  cv::Mat log_likelihoods;
  if (!em->trainEM(data, log_likelihoods, cv::noArray(), cv::noArray()))
    throw InputError(source, "expectation-maximization did not converge");

  const cv::Mat weights = em->getWeights();
  const cv::Mat means = em->getMeans();
  std::vector<cv::Mat> covariances;
  em->getCovs(covariances);
  std::vector<double> component_weights;
  std::vector<Eigen::VectorXd> component_means;
  std::vector<Eigen::MatrixXd> component_covariances;
  const double min_variance = options.min_std_rad * options.min_std_rad;
  for (int k = 0; k < options.num_components; ++k) {
    component_weights.push_back(weights.at<double>(0, k));
    Eigen::VectorXd mean(dims);
    Eigen::MatrixXd covariance(dims, dims);
    for (int i = 0; i < dims; ++i) {
      mean[i] = means.at<double>(k, i);
      for (int j = 0; j < dims; ++j)
        covariance(i, j) = covariances[k].at<double>(i, j);
    }
    covariance.diagonal().array() += min_variance;
    component_means.push_back(mean);
    component_covariances.push_back(covariance);
  }
  PoseMixture mixture;
  try {
    mixture = PoseMixture::FromCovariances(
        character.name(), HingeNames(character), std::move(component_weights),
        std::move(component_means), component_covariances);
  } catch (const ConfigError& e) {
    throw InputError(source, e.what());
  }
  mixture.num_training_frames = static_cast<int>(samples.size());
  if (summary != nullptr) {
    summary->num_samples = static_cast<int>(samples.size());
    summary->mean_log_likelihood = cv::mean(log_likelihoods)[0];
    double cost = 0.0;
    for (const Eigen::VectorXd& sample : samples)
      cost += mixture.Cost(sample.data());
    summary->mean_cost = cost / samples.size();
  }
  return mixture;
}

}  // namespace m2d
