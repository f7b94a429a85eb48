#include "fit/costs.h"

#include <ceres/jet.h>

#include <algorithm>
#include <utility>

namespace m2d {
namespace {

// A cost function whose Jacobians the cost writes itself (`Cost` has
// Evaluate(blocks, residuals, jacobians)).
template <typename Cost>
class AnalyticCostFunction : public ceres::CostFunction {
 public:
  AnalyticCostFunction(Cost cost, const std::vector<int32_t>& block_sizes,
                       int num_residuals)
      : cost_(std::move(cost)) {
    *mutable_parameter_block_sizes() = block_sizes;
    set_num_residuals(num_residuals);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return cost_.Evaluate(parameters, residuals, jacobians);
  }

 private:
  Cost cost_;
};

// A residual's value and its derivative in its argument, through the same
// templated function the residual is defined by.
template <typename Function>
std::pair<double, double> ValueAndSlope(double x, const Function& function) {
  using Jet1 = ceres::Jet<double, 1>;
  const Jet1 y = function(Jet1(x, 0));
  return {y.a, y.v[0]};
}

// The forward kinematics of one frame: points and, when `with_jacobian`,
// their pose Jacobian. Ceres asks for residuals alone at every trial step
// (about half of a fit's evaluations); those skip the Jacobian.
struct PosedPoints {
  int columns = 0;
  std::vector<double> points, jacobian;  // 3 per point; row-major rows

  PosedPoints(const KinematicModel& model, const double* root_m,
              const double* quaternion_wxyz, const double* hinges_rad,
              bool with_jacobian)
      : columns(PoseJacobianColumns(model)),
        points(3 * (model.num_keypoints() + model.num_sole_points())) {
    if (!with_jacobian) {
      CharacterPoints(model, root_m, quaternion_wxyz, hinges_rad,
                      points.data());
      return;
    }
    jacobian.resize(points.size() * columns);
    CharacterPointsWithJacobian(model, root_m, quaternion_wxyz, hinges_rad,
                                points.data(), jacobian.data());
  }

  // Adds scale x gradient . d(point)/d(pose) to one residual's rows of the
  // three pose blocks' Jacobians (root position, quaternion, hinges; each
  // may be null), `gradient` being d(residual)/d(point).
  void AddPoseRow(int point, const double* gradient, int residual, double scale,
                  double* const* pose_jacobians, int num_hinges) const {
    constexpr int kBlockStart[3] = {0, kRootPositionSize,
                                    kRootPositionSize + kRootQuaternionSize};
    const int block_size[3] = {kRootPositionSize, kRootQuaternionSize,
                               num_hinges};
    for (int b = 0; b < 3; ++b) {
      if (pose_jacobians[b] == nullptr) continue;
      double* row = pose_jacobians[b] + residual * block_size[b];
      for (int c = 0; c < 3; ++c) {
        const double factor = scale * gradient[c];
        if (factor == 0.0) continue;
        const double* source =
            jacobian.data() + (3 * point + c) * columns + kBlockStart[b];
        for (int k = 0; k < block_size[b]; ++k) row[k] += factor * source[k];
      }
    }
  }
};

// Zeroes every requested Jacobian block (`rows` residuals each).
void ZeroJacobians(double** jacobians, const std::vector<int32_t>& block_sizes,
                   int rows) {
  if (jacobians == nullptr) return;
  for (size_t b = 0; b < block_sizes.size(); ++b) {
    if (jacobians[b] != nullptr)
      std::fill(jacobians[b], jacobians[b] + rows * block_sizes[b], 0.0);
  }
}

std::vector<int32_t> FrameBlockSizes(const KinematicModel& model) {
  return {1, 2, 3, kRootPositionSize, kRootQuaternionSize, model.num_hinges()};
}

std::vector<int32_t> SlideBlockSizes(const KinematicModel& model) {
  const int32_t hinges = model.num_hinges();
  return {kRootPositionSize, kRootQuaternionSize, hinges,
          kRootPositionSize, kRootQuaternionSize, hinges};
}

std::vector<int32_t> SelfContactBlockSizes(const KinematicModel& model) {
  return {kRootPositionSize, kRootQuaternionSize, model.num_hinges()};
}

std::vector<int32_t> BalanceBlockSizes(const KinematicModel& model) {
  std::vector<int32_t> sizes;
  for (int frame = 0; frame < 3; ++frame) {
    sizes.insert(sizes.end(),
                 {kRootPositionSize, kRootQuaternionSize, model.num_hinges()});
  }
  return sizes;
}

}  // namespace

bool FrameCost::Evaluate(double const* const* blocks, double* residuals,
                         double** jacobians) const {
  // Outline: the frame's points and pose Jacobian; per used keypoint the
  // projection with its derivatives in the camera and the point (Jets),
  // chained through the robust residual; the floor, penetration and upright
  // rows. Jacobian rows start at zero and terms add into them.
  using Jet10 = ceres::Jet<double, 10>;
  using Jet4 = ceres::Jet<double, 4>;
  const int num_keypoints = model->num_keypoints();
  const int num_soles = model->num_sole_points();
  const int num_hinges = model->num_hinges();
  const bool want = jacobians != nullptr;
  ZeroJacobians(jacobians, BlockSizes(), NumResiduals(*model));
  // The pose's Jacobian only when a pose block is free (a rig camera's
  // placement holds the body).
  const bool want_pose = want && (jacobians[3] || jacobians[4] || jacobians[5]);
  const PosedPoints posed(*model, blocks[3], blocks[4], blocks[5], want_pose);
  double* const no_pose[3] = {nullptr, nullptr, nullptr};
  double* const* pose_jacobians = want_pose ? jacobians + 3 : no_pose;

  // Reprojection: residual rows 2j, 2j + 1.
  const Jet10 focal(blocks[0][0], 0);
  const Jet10 pitch_roll[2] = {Jet10(blocks[1][0], 1), Jet10(blocks[1][1], 2)};
  const Jet10 centre[3] = {Jet10(blocks[2][0], 3), Jet10(blocks[2][1], 4),
                           Jet10(blocks[2][2], 5)};
  const Jet10 yaw = camera_yaw ? Jet10(blocks[6][0], 9) : Jet10(0.0);
  for (int j = 0; j < num_keypoints; ++j) {
    if (weights[j] == 0.0) {
      residuals[2 * j] = residuals[2 * j + 1] = 0.0;
      continue;
    }
    const double* p = &posed.points[3 * j];
    const Jet10 point[3] = {Jet10(p[0], 6), Jet10(p[1], 7), Jet10(p[2], 8)};
    Jet10 pixel[2];
    if (camera_yaw) {
      FitProjectTurned(focal, pitch_roll, yaw, centre, point, cx_px, cy_px,
                       pixel);
    } else {
      FitProject(focal, pitch_roll, centre, point, cx_px, cy_px, pixel);
    }
    for (int k = 0; k < 2; ++k) {
      const int row = 2 * j + k;
      const auto [value, slope] = ValueAndSlope(
          (pixel[k].a - observed_px[j][k]) * inv_scale_px,
          [&](const auto& e) { return GemanMcClureResidual(e, sigma); });
      residuals[row] = weights[j] * value;
      if (!want) continue;
      const double d_pixel = weights[j] * slope * inv_scale_px;
      const Eigen::Matrix<double, 10, 1>& d = pixel[k].v;
      if (jacobians[0]) jacobians[0][row] = d_pixel * d[0];
      if (jacobians[1]) {
        for (int c = 0; c < 2; ++c)
          jacobians[1][2 * row + c] = d_pixel * d[1 + c];
      }
      if (jacobians[2]) {
        for (int c = 0; c < 3; ++c)
          jacobians[2][3 * row + c] = d_pixel * d[3 + c];
      }
      if (camera_yaw && jacobians[6]) jacobians[6][row] = d_pixel * d[9];
      const double gradient[3] = {d[6], d[7], d[8]};
      posed.AddPoseRow(j, gradient, row, d_pixel, pose_jacobians, num_hinges);
    }
  }

  // Floor (the lowest sole point) and penetration (each sole point).
  double* out = residuals + 2 * num_keypoints;
  const int ground_row = 2 * num_keypoints;
  int lowest = 0;
  for (int s = 0; s < num_soles; ++s) {
    const double z = posed.points[3 * (num_keypoints + s) + 2];
    if (z < posed.points[3 * (num_keypoints + lowest) + 2]) lowest = s;
    out[1 + s] = z < 0.0 ? penetration_weight * z : 0.0;
    if (want && z < 0.0) {
      const double up[3] = {0, 0, 1};
      posed.AddPoseRow(num_keypoints + s, up, ground_row + 1 + s,
                       penetration_weight, pose_jacobians, num_hinges);
    }
  }
  const auto [ground, ground_slope] = ValueAndSlope(
      posed.points[3 * (num_keypoints + lowest) + 2],
      [&](const auto& z) { return GemanMcClureResidual(z, airborne_m); });
  out[0] = ground_weight * ground;
  if (want) {
    const double up[3] = {0, 0, 1};
    posed.AddPoseRow(num_keypoints + lowest, up, ground_row,
                     ground_weight * ground_slope, pose_jacobians, num_hinges);
  }

  // Upright: the horizontal part of the root's up axis (the rotation's third
  // column), in the quaternion alone.
  const int upright_row = ground_row + 1 + num_soles;
  Jet4 q[4];
  for (int k = 0; k < 4; ++k) q[k] = Jet4(blocks[4][k], k);
  const Jet4 norm2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
  const Jet4 upright[2] = {
      upright_weight * 2.0 * (q[1] * q[3] + q[0] * q[2]) / norm2,
      upright_weight * 2.0 * (q[2] * q[3] - q[0] * q[1]) / norm2};
  for (int k = 0; k < 2; ++k) {
    residuals[upright_row + k] = upright[k].a;
    if (want && jacobians[4]) {
      for (int c = 0; c < 4; ++c)
        jacobians[4][4 * (upright_row + k) + c] = upright[k].v[c];
    }
  }
  return true;
}

std::vector<int32_t> FrameCost::BlockSizes() const {
  std::vector<int32_t> sizes = FrameBlockSizes(*model);
  if (camera_yaw) sizes.push_back(1);
  return sizes;
}

ceres::CostFunction* FrameCost::Create(FrameCost cost) {
  const std::vector<int32_t> sizes = cost.BlockSizes();
  const int num_residuals = NumResiduals(*cost.model);
  return new AnalyticCostFunction<FrameCost>(std::move(cost), sizes,
                                             num_residuals);
}

ceres::CostFunction* LimbCost::Create(LimbCost cost) {
  const KinematicModel& model = *cost.model;
  const int num_joints = static_cast<int>(model.joints.size());
  cost.fixed_orientation.assign(num_joints, Eigen::Matrix3d::Identity());
  cost.fixed_position.assign(num_joints, Eigen::Vector3d::Zero());
  JointFrames(model, cost.root_m, cost.quaternion_wxyz, cost.hinges_rad.data(),
              cost.fixed_orientation.data(), cost.fixed_position.data());
  cost.moves = JointsMovedBy(model, cost.limb_hinges);
  const int num_limb_hinges = static_cast<int>(cost.limb_hinges.size());
  const int num_residuals = cost.NumResiduals();
  auto* function = new ceres::DynamicAutoDiffCostFunction<LimbCost, 4>(
      new LimbCost(std::move(cost)));
  function->AddParameterBlock(num_limb_hinges);
  function->SetNumResiduals(num_residuals);
  return function;
}

bool FootSlideCost::Evaluate(double const* const* blocks, double* residuals,
                             double** jacobians) const {
  // Outline: both frames' points and pose Jacobians; per sole point its
  // weighted horizontal step, minus the first frame's rows and plus the
  // second's.
  const int num_keypoints = model->num_keypoints();
  const int num_soles = model->num_sole_points();
  const int num_hinges = model->num_hinges();
  ZeroJacobians(jacobians, SlideBlockSizes(*model), 2 * num_soles);
  const bool want = jacobians != nullptr;
  const PosedPoints before(*model, blocks[0], blocks[1], blocks[2], want);
  const PosedPoints after(*model, blocks[3], blocks[4], blocks[5], want);
  for (int s = 0; s < num_soles; ++s) {
    const int point = num_keypoints + s;
    for (int k = 0; k < 2; ++k) {
      const int row = 2 * s + k;
      residuals[row] = contact_weights[s] * (after.points[3 * point + k] -
                                             before.points[3 * point + k]);
      if (jacobians == nullptr) continue;
      const double axis[3] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, 0.0};
      before.AddPoseRow(point, axis, row, -contact_weights[s], jacobians,
                        num_hinges);
      after.AddPoseRow(point, axis, row, contact_weights[s], jacobians + 3,
                       num_hinges);
    }
  }
  return true;
}

ceres::CostFunction* FootSlideCost::Create(FootSlideCost cost) {
  const std::vector<int32_t> sizes = SlideBlockSizes(*cost.model);
  const int num_residuals = 2 * cost.model->num_sole_points();
  return new AnalyticCostFunction<FootSlideCost>(std::move(cost), sizes,
                                                 num_residuals);
}

bool SelfContactCost::Evaluate(double const* const* blocks, double* residuals,
                               double** jacobians) const {
  // Outline: the centres of the spheres the pairs name, with their pose
  // Jacobian; per pair the overlap r_a + r_b - |c_a - c_b| (0 when apart)
  // and, where they overlap, its derivative -u . (dc_a - dc_b), u the unit
  // vector from b to a.
  const int num_hinges = model->num_hinges();
  const int columns = PoseJacobianColumns(*model);
  const int num_pairs = static_cast<int>(pairs.size());
  ZeroJacobians(jacobians, SelfContactBlockSizes(*model), num_pairs);
  std::vector<int> slot(model->collision_spheres.size(), -1);
  std::vector<BodyPoint> centres;
  for (const auto& [a, b] : pairs) {
    for (int sphere : {a, b}) {
      if (slot[sphere] >= 0) continue;
      slot[sphere] = static_cast<int>(centres.size());
      centres.push_back(model->collision_spheres[sphere].centre);
    }
  }
  std::vector<double> points(3 * centres.size());
  std::vector<double> jacobian;
  if (jacobians != nullptr) jacobian.resize(points.size() * columns);
  BodyPointsWithJacobian(*model, blocks[0], blocks[1], blocks[2], centres,
                         points.data(),
                         jacobians != nullptr ? jacobian.data() : nullptr);
  constexpr int kBlockStart[3] = {0, kRootPositionSize,
                                  kRootPositionSize + kRootQuaternionSize};
  const int block_size[3] = {kRootPositionSize, kRootQuaternionSize,
                             num_hinges};
  for (int r = 0; r < num_pairs; ++r) {
    const auto [a, b] = pairs[r];
    const Eigen::Vector3d from_b =
        Eigen::Map<const Eigen::Vector3d>(&points[3 * slot[a]]) -
        Eigen::Map<const Eigen::Vector3d>(&points[3 * slot[b]]);
    const double distance_m = from_b.norm();
    const double overlap_m = model->collision_spheres[a].radius_m +
                             model->collision_spheres[b].radius_m - distance_m;
    residuals[r] = overlap_m > 0.0 ? weight * overlap_m : 0.0;
    if (jacobians == nullptr || overlap_m <= 0.0 || distance_m < 1e-9) continue;
    const Eigen::Vector3d unit = from_b / distance_m;
    for (int k = 0; k < 3; ++k) {
      if (jacobians[k] == nullptr) continue;
      double* row = jacobians[k] + r * block_size[k];
      for (int c = 0; c < 3; ++c) {
        const double* row_a =
            jacobian.data() + (3 * slot[a] + c) * columns + kBlockStart[k];
        const double* row_b =
            jacobian.data() + (3 * slot[b] + c) * columns + kBlockStart[k];
        for (int i = 0; i < block_size[k]; ++i)
          row[i] -= weight * unit[c] * (row_a[i] - row_b[i]);
      }
    }
  }
  return true;
}

ceres::CostFunction* SelfContactCost::Create(SelfContactCost cost) {
  const std::vector<int32_t> sizes = SelfContactBlockSizes(*cost.model);
  const int num_residuals = static_cast<int>(cost.pairs.size());
  return new AnalyticCostFunction<SelfContactCost>(std::move(cost), sizes,
                                                   num_residuals);
}

bool BalanceCost::Evaluate(double const* const* blocks, double* residuals,
                           double** jacobians) const {
  // Outline: the three frames' centres of mass with their Jacobians; the
  // zero-moment point as 9-wide Jets in those centres; frame t's support
  // box; per axis the distance outside it, chained into the pose blocks
  // (through the centres, and through the sole point that bounds the box).
  using Jet9 = ceres::Jet<double, 9>;
  constexpr double kGravity_m_s2 = 9.81;
  const int num_hinges = model->num_hinges();
  const int columns = PoseJacobianColumns(*model);
  ZeroJacobians(jacobians, BalanceBlockSizes(*model), 2);
  double com[3][3];
  std::vector<double> com_jacobian[3];
  for (int f = 0; f < 3; ++f) {
    if (jacobians != nullptr) com_jacobian[f].resize(3 * columns);
    CenterOfMassWithJacobian(
        *model, blocks[3 * f], blocks[3 * f + 1], blocks[3 * f + 2], com[f],
        jacobians != nullptr ? com_jacobian[f].data() : nullptr);
  }
  Jet9 c[3][3];
  for (int f = 0; f < 3; ++f)
    for (int k = 0; k < 3; ++k) c[f][k] = Jet9(com[f][k], 3 * f + k);
  const double inv_span2 = 1.0 / (span_s * span_s);
  Jet9 acceleration[3];
  for (int k = 0; k < 3; ++k)
    acceleration[k] = (c[0][k] - 2.0 * c[1][k] + c[2][k]) * inv_span2;
  // A body falling faster than 0.8 g has no support to balance on; the
  // floor keeps the division finite.
  Jet9 vertical = acceleration[2] + kGravity_m_s2;
  if (vertical.a < 0.2 * kGravity_m_s2) vertical = Jet9(0.2 * kGravity_m_s2);
  const Jet9 zmp[2] = {c[1][0] - c[1][2] * acceleration[0] / vertical,
                       c[1][1] - c[1][2] * acceleration[1] / vertical};

  const PosedPoints posed(*model, blocks[3], blocks[4], blocks[5],
                          jacobians != nullptr);
  const int first_sole = model->num_keypoints();
  for (int k = 0; k < 2; ++k) {
    // The support box along this axis: its in-contact sole points' extent.
    int low = -1, high = -1;
    for (int s = 0; s < model->num_sole_points(); ++s) {
      if (!in_contact[s]) continue;
      const double x = posed.points[3 * (first_sole + s) + k];
      if (low < 0 || x < posed.points[3 * (first_sole + low) + k]) low = s;
      if (high < 0 || x > posed.points[3 * (first_sole + high) + k]) high = s;
    }
    residuals[k] = 0.0;
    if (low < 0) continue;
    const double low_m = posed.points[3 * (first_sole + low) + k] - margin_m;
    const double high_m = posed.points[3 * (first_sole + high) + k] + margin_m;
    int bound = -1;
    if (zmp[k].a < low_m) {
      residuals[k] = weight * (zmp[k].a - low_m);
      bound = low;
    } else if (zmp[k].a > high_m) {
      residuals[k] = weight * (zmp[k].a - high_m);
      bound = high;
    }
    if (jacobians == nullptr || bound < 0) continue;
    // Through the centres of mass: d zmp / d c[f] times c[f]'s rows.
    for (int f = 0; f < 3; ++f) {
      for (int part = 0; part < 3; ++part) {
        double* jacobian = jacobians[3 * f + part];
        if (jacobian == nullptr) continue;
        const int start = part == 0   ? 0
                          : part == 1 ? kRootPositionSize
                                      : kRootPositionSize + kRootQuaternionSize;
        const int size = part == 0   ? kRootPositionSize
                         : part == 1 ? kRootQuaternionSize
                                     : num_hinges;
        double* row = jacobian + k * size;
        for (int i = 0; i < 3; ++i) {
          const double factor = weight * zmp[k].v[3 * f + i];
          if (factor == 0.0) continue;
          const double* source = com_jacobian[f].data() + i * columns + start;
          for (int col = 0; col < size; ++col) row[col] += factor * source[col];
        }
      }
    }
    // Through the bounding sole point of frame t.
    const double axis[3] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, 0.0};
    posed.AddPoseRow(first_sole + bound, axis, k, -weight, jacobians + 3,
                     num_hinges);
  }
  return true;
}

std::vector<int32_t> LeanBlockSizes(const KinematicModel& model) {
  return {kRootPositionSize, kRootQuaternionSize, model.num_hinges()};
}

bool LeanCost::Evaluate(double const* const* blocks, double* residuals,
                        double** jacobians) const {
  // Outline: the centre of mass and the posed sole points, each with its
  // Jacobian; the offset; its rows chained into the three pose blocks.
  const int num_hinges = model->num_hinges();
  const int columns = PoseJacobianColumns(*model);
  ZeroJacobians(jacobians, LeanBlockSizes(*model), 2);
  double com[3];
  std::vector<double> com_jacobian(jacobians != nullptr ? 3 * columns : 0);
  CenterOfMassWithJacobian(
      *model, blocks[0], blocks[1], blocks[2], com,
      jacobians != nullptr ? com_jacobian.data() : nullptr);
  const PosedPoints posed(*model, blocks[0], blocks[1], blocks[2],
                          jacobians != nullptr);
  const int first_sole = model->num_keypoints();
  double total = 0.0;
  for (double w : contact_weights) total += w;
  for (int k = 0; k < 2; ++k) {
    double support_m = 0.0;
    for (int s = 0; s < model->num_sole_points(); ++s)
      support_m += contact_weights[s] * posed.points[3 * (first_sole + s) + k];
    residuals[k] = weight * (com[k] - support_m / total - target_m[k]);
  }
  if (jacobians == nullptr) return true;
  constexpr int kBlockStart[3] = {0, kRootPositionSize,
                                  kRootPositionSize + kRootQuaternionSize};
  const int block_size[3] = {kRootPositionSize, kRootQuaternionSize,
                             num_hinges};
  // The offset does not depend on the root's position (the centre of mass
  // and the soles move with it alike): that block stays 0, exactly.
  double* const pose_jacobians[3] = {nullptr, jacobians[1], jacobians[2]};
  for (int k = 0; k < 2; ++k) {
    for (int b = 1; b < 3; ++b) {
      if (jacobians[b] == nullptr) continue;
      double* row = jacobians[b] + k * block_size[b];
      const double* source = com_jacobian.data() + k * columns + kBlockStart[b];
      for (int col = 0; col < block_size[b]; ++col)
        row[col] += weight * source[col];
    }
    double gradient[3] = {0.0, 0.0, 0.0};
    gradient[k] = 1.0;
    for (int s = 0; s < model->num_sole_points(); ++s) {
      if (contact_weights[s] == 0.0) continue;
      posed.AddPoseRow(first_sole + s, gradient, k,
                       -weight * contact_weights[s] / total, pose_jacobians,
                       num_hinges);
    }
  }
  return true;
}

ceres::CostFunction* LeanCost::Create(LeanCost cost) {
  const std::vector<int32_t> sizes = LeanBlockSizes(*cost.model);
  return new AnalyticCostFunction<LeanCost>(std::move(cost), sizes, 2);
}

ceres::CostFunction* BalanceCost::Create(BalanceCost cost) {
  const std::vector<int32_t> sizes = BalanceBlockSizes(*cost.model);
  return new AnalyticCostFunction<BalanceCost>(std::move(cost), sizes, 2);
}

}  // namespace m2d
