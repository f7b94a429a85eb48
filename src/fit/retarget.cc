#include "fit/retarget.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "fit/kinematics.h"
#include "sim/character.h"

namespace m2d {
namespace {

// Weighted distances of the character's keypoints to their targets, and the
// hinges' pulls toward rest and toward the previous frame. Blocks: root
// position (3), root quaternion (4), hinge angles.
struct KeypointFitCost {
  const KinematicModel* model;
  std::vector<Eigen::Vector3d> targets_m;
  std::vector<double> weights;
  std::vector<double> previous_rad;  // empty: no continuity term
  double rest_weight = 0.0;
  double continuity_weight = 0.0;

  template <typename T>
  bool operator()(T const* const* blocks, T* residuals) const {
    T points[3 * kMaxFitPoints];
    CharacterPoints(*model, blocks[0], blocks[1], blocks[2], points);
    T* out = residuals;
    for (size_t j = 0; j < targets_m.size(); ++j)
      for (int c = 0; c < 3; ++c)
        *out++ = T(weights[j]) * (points[3 * j + c] - T(targets_m[j][c]));
    for (int h = 0; h < model->num_hinges(); ++h) {
      *out++ = T(rest_weight) * blocks[2][h];
      *out++ = previous_rad.empty()
                   ? T(0)
                   : T(continuity_weight) * (blocks[2][h] - T(previous_rad[h]));
    }
    return true;
  }
};

// Sum of the upper- and lower-limb lengths (both arms and legs) of one
// frame's COCO-17 points.
double LimbLengthM(const KeypointLayout& layout,
                   const std::vector<Eigen::Vector3d>& points) {
  double total = 0.0;
  for (const char* side : {"left_", "right_"}) {
    const std::string s(side);
    for (const auto& [a, b] :
         {std::pair{"shoulder", "elbow"}, std::pair{"elbow", "wrist"},
          std::pair{"hip", "knee"}, std::pair{"knee", "ankle"}}) {
      total += (points[layout.IndexOf(s + a)] - points[layout.IndexOf(s + b)])
                   .norm();
    }
  }
  return total;
}

std::vector<Eigen::Vector3d> PointsOf(const KinematicModel& model,
                                      const double* root, const double* q,
                                      const double* hinges) {
  std::vector<double> flat(3 *
                           (model.num_keypoints() + model.num_sole_points()));
  CharacterPoints(model, root, q, hinges, flat.data());
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < model.num_keypoints(); ++j)
    points.emplace_back(flat[3 * j], flat[3 * j + 1], flat[3 * j + 2]);
  return points;
}

}  // namespace

std::vector<Eigen::VectorXd> RetargetKeypointsToHinges(
    const Character& character,
    const std::vector<std::vector<Eigen::Vector3d>>& keypoints_m,
    const RetargetOptions& options, const std::string& source,
    RetargetSummary* summary, const std::vector<Eigen::VectorXd>* starts_rad) {
  // Outline: check the points; scale them to the character's limb lengths;
  // per frame, place the root by the torso (a similarity fit of shoulders
  // and hips) and solve for the root and hinges, warm-started from the
  // previous frame or the given start.
  const KinematicModel model = KinematicModel::FromCharacter(character);
  const KeypointLayout& layout = character.keypoint_layout();
  const int num_keypoints = model.num_keypoints();
  for (size_t t = 0; t < keypoints_m.size(); ++t) {
    bool finite = static_cast<int>(keypoints_m[t].size()) == num_keypoints;
    for (const Eigen::Vector3d& p : keypoints_m[t])
      finite = finite && p.allFinite();
    if (!finite) {
      throw InputError(source, "frame " + std::to_string(t) + " has not " +
                                   std::to_string(num_keypoints) +
                                   " finite 3D keypoints");
    }
  }
  if (keypoints_m.empty()) throw InputError(source, "no frames to retarget");
  if (starts_rad != nullptr) {
    bool shaped = starts_rad->size() == keypoints_m.size();
    for (const Eigen::VectorXd& start : *starts_rad)
      shaped =
          shaped && start.size() == model.num_hinges() && start.allFinite();
    if (!shaped) {
      throw InputError(source, "retarget starts: need " +
                                   std::to_string(keypoints_m.size()) +
                                   " frames of " +
                                   std::to_string(model.num_hinges()) +
                                   " finite hinge angles");
    }
  }

  std::vector<double> rest(model.num_hinges());
  for (int h = 0; h < model.num_hinges(); ++h)
    rest[h] = std::clamp(0.0, model.hinge_low_rad[h], model.hinge_high_rad[h]);
  const double origin[3] = {0, 0, 0};
  const double identity[4] = {1, 0, 0, 0};
  const std::vector<Eigen::Vector3d> rest_points =
      PointsOf(model, origin, identity, rest.data());
  std::vector<double> source_lengths;
  for (const auto& frame : keypoints_m)
    source_lengths.push_back(LimbLengthM(layout, frame));
  std::nth_element(source_lengths.begin(),
                   source_lengths.begin() + source_lengths.size() / 2,
                   source_lengths.end());
  const double scale = LimbLengthM(layout, rest_points) /
                       source_lengths[source_lengths.size() / 2];

  std::vector<double> weights(num_keypoints, 1.0);
  for (const char* face :
       {"nose", "left_eye", "right_eye", "left_ear", "right_ear"}) {
    const int index = layout.IndexOf(face);
    if (index >= 0) weights[index] = options.face_weight;
  }
  std::vector<int> torso;
  for (const char* name :
       {"left_shoulder", "right_shoulder", "left_hip", "right_hip"})
    torso.push_back(layout.IndexOf(name));

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.logging_type = ceres::SILENT;
  std::vector<Eigen::VectorXd> result;
  std::vector<double> hinges = rest;
  std::vector<double> previous;
  double error_sum = 0.0, worst = 0.0;
  std::vector<double> frame_mean_m, frame_worst_m;
  for (size_t t = 0; t < keypoints_m.size(); ++t) {
    if (starts_rad != nullptr) {
      for (int h = 0; h < model.num_hinges(); ++h) {
        hinges[h] = std::clamp((*starts_rad)[t][h], model.hinge_low_rad[h],
                               model.hinge_high_rad[h]);
      }
    }
    std::vector<Eigen::Vector3d> targets;
    for (const Eigen::Vector3d& p : keypoints_m[t])
      targets.push_back(scale * p);
    // The root from the torso: the rigid motion taking the rest pose's
    // shoulders and hips onto the target's.
    Eigen::Matrix<double, 3, 4> from, to;
    for (int i = 0; i < 4; ++i) {
      from.col(i) = rest_points[torso[i]];
      to.col(i) = targets[torso[i]];
    }
    const Eigen::Matrix4d transform = Eigen::umeyama(from, to, false);
    double root[3] = {transform(0, 3), transform(1, 3), transform(2, 3)};
    const Eigen::Quaterniond turn(Eigen::Matrix3d(transform.block<3, 3>(0, 0)));
    double quaternion[4] = {turn.w(), turn.x(), turn.y(), turn.z()};

    auto* cost = new KeypointFitCost{&model,
                                     targets,
                                     weights,
                                     previous,
                                     options.rest_weight,
                                     options.continuity_weight};
    auto* function =
        new ceres::DynamicAutoDiffCostFunction<KeypointFitCost, 8>(cost);
    function->AddParameterBlock(3);
    function->AddParameterBlock(4);
    function->AddParameterBlock(model.num_hinges());
    function->SetNumResiduals(3 * num_keypoints + 2 * model.num_hinges());
    ceres::Problem problem;
    problem.AddResidualBlock(function, nullptr,
                             {root, quaternion, hinges.data()});
    problem.SetManifold(quaternion, new ceres::QuaternionManifold());
    for (int h = 0; h < model.num_hinges(); ++h) {
      problem.SetParameterLowerBound(hinges.data(), h, model.hinge_low_rad[h]);
      problem.SetParameterUpperBound(hinges.data(), h, model.hinge_high_rad[h]);
    }
    ceres::Solver::Summary solved;
    ceres::Solve(solver, &problem, &solved);

    const std::vector<Eigen::Vector3d> placed =
        PointsOf(model, root, quaternion, hinges.data());
    double frame_error = 0.0, frame_worst = 0.0;
    int counted = 0;
    for (int j = 0; j < num_keypoints; ++j) {
      if (weights[j] < 1.0) continue;
      const double distance_m = (placed[j] - targets[j]).norm();
      frame_error += distance_m;
      frame_worst = std::max(frame_worst, distance_m);
      ++counted;
    }
    frame_error /= counted;
    frame_mean_m.push_back(frame_error);
    frame_worst_m.push_back(frame_worst);
    error_sum += frame_error;
    worst = std::max(worst, frame_error);
    result.push_back(
        Eigen::Map<const Eigen::VectorXd>(hinges.data(), model.num_hinges()));
    previous = hinges;
  }
  if (summary != nullptr) {
    summary->num_frames = static_cast<int>(keypoints_m.size());
    summary->scale = scale;
    summary->mean_error_m = error_sum / keypoints_m.size();
    summary->worst_frame_error_m = worst;
    summary->frame_mean_error_m = std::move(frame_mean_m);
    summary->frame_worst_error_m = std::move(frame_worst_m);
  }
  return result;
}

}  // namespace m2d
