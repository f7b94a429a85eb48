// fit: the terms of the fit's objective as Ceres cost functions. docs/fit.md
// writes each one out. Every term returns weighted residuals; Ceres
// minimizes half their squared sum. The per-frame terms that run the forward
// kinematics (FrameCost, FootSlideCost) have analytic Jacobians (costs.cc);
// the others are templated functors for automatic differentiation.
#ifndef MIMIC2D_FIT_COSTS_H_
#define MIMIC2D_FIT_COSTS_H_

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "fit/camera_model.h"
#include "fit/kinematics.h"
#include "fit/pose_prior.h"

namespace m2d {

// Per-coordinate Geman-McClure as a residual: its square is SMPLify's GMoF
// sigma^2 x^2 / (sigma^2 + x^2); smooth, ~x near 0, bounded by sigma.
template <typename T>
T GemanMcClureResidual(const T& x, double sigma) {
  using std::sqrt;
  return x * T(sigma) / sqrt(T(sigma * sigma) + x * x);
}

// One frame's terms, sharing one forward-kinematics pass. Parameter blocks:
// focal (1), camera pitch and roll (2), camera centre (3), root position
// (3), root quaternion (4), hinge angles (model.num_hinges()). Residuals:
//  - reprojection, 2 per keypoint: weight x Geman-McClure of the pixel
//    error in units of the person's image size (0 for unused keypoints);
//  - ground, 1: the lowest sole point's height, bounded Geman-McClure style
//    by `airborne_m` so that a jump is not pulled down;
//  - penetration, 1 per sole point: its height when below z = 0;
//  - upright, 2: the horizontal part of the root's up axis (people stand
//    upright on average; it keeps camera roll from hiding in a lean).
// With `camera_yaw` a seventh block, the camera's yaw (1): a rig's other
// cameras (FitRig), whose terms beyond the reprojection are weighted 0 (the
// body's are counted once, with the first camera).
struct FrameCost {
  const KinematicModel* model;
  std::vector<Eigen::Vector2d> observed_px;  // per keypoint
  std::vector<double> weights;               // per keypoint (0: unused)
  double cx_px = 0.0, cy_px = 0.0;
  double inv_scale_px = 1.0;  // 1 / the person's image size
  double sigma = 0.5;         // Geman-McClure sigma, same units
  double ground_weight = 0.0;
  double penetration_weight = 0.0;
  double airborne_m = 0.15;
  double upright_weight = 0.0;
  bool camera_yaw = false;

  static int NumResiduals(const KinematicModel& model) {
    return 2 * model.num_keypoints() + 1 + model.num_sole_points() + 2;
  }

  // Residuals and, for the blocks `jacobians` asks for, their derivatives:
  // the pose's from CharacterPointsWithJacobian, the projection's through
  // 10-wide Jets (camera with its yaw, and point).
  bool Evaluate(double const* const* blocks, double* residuals,
                double** jacobians) const;

  // The blocks' sizes, in the order above.
  std::vector<int32_t> BlockSizes() const;

  static ceres::CostFunction* Create(FrameCost cost);
};

// One limb of one frame with everything else held (the limb search, stage
// 1b): a single block, the limb's hinge angles. Residuals: the limb's
// keypoints' reprojection as in FrameCost, each sole point's penetration,
// and the prior toward rest on the limb's hinges. Differentiating only the
// few limb angles keeps the many small solves of the search cheap.
struct LimbCost {
  const KinematicModel* model;
  std::vector<int> limb_hinges;              // indices into `hinges_rad`
  std::vector<int> keypoints;                // the limb's, layout indices
  std::vector<Eigen::Vector2d> observed_px;  // per limb keypoint
  std::vector<double> weights;               // per limb keypoint
  std::vector<double> hinges_rad;            // the frame's, all of them
  double root_m[3] = {0, 0, 0};
  double quaternion_wxyz[4] = {1, 0, 0, 0};
  double focal_px = 1.0;
  double pitch_roll_rad[2] = {0, 0};
  double centre_m[3] = {0, 0, 0};
  double cx_px = 0.0, cy_px = 0.0;
  double inv_scale_px = 1.0;
  double sigma = 0.5;
  double penetration_weight = 0.0;
  double prior_weight = 0.0;  // toward rest, per rad
  // The learned prior's marginal over the limb's hinges (null: toward
  // rest), weighted per standard deviation as MixturePriorCost.
  const PoseMixture* limb_mixture = nullptr;
  double mixture_weight = 0.0;

  // Filled by Create from the fields above: every joint's frame at
  // `hinges_rad` and which joints the limb's hinges move. Only those are
  // composed in Jets; the rest of the body is constant in this problem.
  std::vector<char> moves;
  std::vector<Eigen::Matrix3d> fixed_orientation;
  std::vector<Eigen::Vector3d> fixed_position;

  int NumResiduals() const {
    return 2 * static_cast<int>(keypoints.size()) + model->num_sole_points() +
           static_cast<int>(limb_hinges.size()) + 1;
  }

  // A body point's world position: composed in Jets when the limb moves
  // its joint, constant otherwise.
  template <typename T>
  fk_internal::Vector3<T> PointAt(
      const BodyPoint& point, const fk_internal::Matrix3<T>* orientation,
      const fk_internal::Vector3<T>* position) const {
    if (moves[point.joint]) {
      return position[point.joint] +
             orientation[point.joint] * point.offset_m.cast<T>();
    }
    return (fixed_position[point.joint] +
            fixed_orientation[point.joint] * point.offset_m)
        .template cast<T>();
  }

  template <typename T>
  bool operator()(T const* const* blocks, T* residuals) const {
    constexpr int kMaxHinges = 128;
    T hinges[kMaxHinges];
    for (size_t h = 0; h < hinges_rad.size(); ++h) hinges[h] = T(hinges_rad[h]);
    for (size_t i = 0; i < limb_hinges.size(); ++i)
      hinges[limb_hinges[i]] = blocks[0][i];
    fk_internal::Matrix3<T> orientation[kMaxFitJoints];
    fk_internal::Vector3<T> position[kMaxFitJoints];
    MovedJointFrames(*model, moves, fixed_orientation.data(),
                     fixed_position.data(), hinges, orientation, position);
    const T focal(focal_px);
    const T pitch_roll[2] = {T(pitch_roll_rad[0]), T(pitch_roll_rad[1])};
    const T centre[3] = {T(centre_m[0]), T(centre_m[1]), T(centre_m[2])};
    T* out = residuals;
    for (size_t k = 0; k < keypoints.size(); ++k, out += 2) {
      const fk_internal::Vector3<T> point =
          PointAt(model->keypoints[keypoints[k]], orientation, position);
      T pixel[2];
      FitProject(focal, pitch_roll, centre, point.data(), cx_px, cy_px, pixel);
      for (int c = 0; c < 2; ++c) {
        const T error = (pixel[c] - T(observed_px[k][c])) * T(inv_scale_px);
        out[c] = T(weights[k]) * GemanMcClureResidual(error, sigma);
      }
    }
    for (const BodyPoint& sole : model->sole_points) {
      const T z = PointAt(sole, orientation, position)[2];
      *out++ = z < T(0) ? T(penetration_weight) * z : T(0);
    }
    const int num_limb_hinges = static_cast<int>(limb_hinges.size());
    if (limb_mixture == nullptr) {
      for (int i = 0; i < num_limb_hinges; ++i, ++out)
        *out = T(prior_weight) * blocks[0][i];
      *out = T(0);
      return true;
    }
    MixtureResiduals(*limb_mixture, mixture_weight, blocks[0], out);
    return true;
  }

  // Fills the derived fields, then the cost function. A limb has 3-4
  // hinges: Jets 4 wide take them in one pass.
  static ceres::CostFunction* Create(LimbCost cost);
};

// Feet that do not slide (blocks: frame t's root position, quaternion,
// hinges, then frame t+1's): each sole point's horizontal step, weighted by
// how surely it is in contact (fixed during a solve).
struct FootSlideCost {
  const KinematicModel* model;
  std::vector<double> contact_weights;  // per sole point

  // Residuals and requested Jacobians (analytic, from
  // CharacterPointsWithJacobian).
  bool Evaluate(double const* const* blocks, double* residuals,
                double** jacobians) const;

  static ceres::CostFunction* Create(FootSlideCost cost);
};

// Bodies that do not pass through each other (blocks: one frame's root
// position, quaternion, hinges): per pair of the character's collision
// spheres (KinematicModel::collision_pairs) chosen when the solve is built,
// weight x how deeply the two overlap (m; 0 when apart). SMPLify's
// interpenetration term with spheres for capsules: without it, 2D lets a
// leg pass behind the other through it, or a forearm through the waist.
struct SelfContactCost {
  const KinematicModel* model;
  std::vector<std::pair<int, int>> pairs;  // indices of collision spheres
  double weight = 0.0;

  // Residuals and requested Jacobians (analytic, BodyPointsWithJacobian).
  bool Evaluate(double const* const* blocks, double* residuals,
                double** jacobians) const;

  static ceres::CostFunction* Create(SelfContactCost cost);
};

// Balance (blocks: the root position, quaternion and hinges of frames
// t - k, t and t + k): the zero-moment point of frame t, from the centre of
// mass c and its acceleration a = (c[t-k] - 2 c[t] + c[t+k]) / (k dt)^2
// (the cart-table model, angular momentum left out),
//   zmp = c_xy - c_z a_xy / (g + a_z),
// must lie within the support: the horizontal box of frame t's in-contact
// sole points, grown by `margin_m`. Residuals, 2: weight x how far the zmp
// lies outside the box along x and y (0 inside). Gravity is the one
// direction 2D does not show; a body leaning with nothing under it is how a
// wrong camera pitch or roll hides, and this is what rules it out.
struct BalanceCost {
  const KinematicModel* model;
  std::vector<bool> in_contact;  // per sole point, at frame t
  double span_s = 0.1;           // k dt
  double margin_m = 0.05;
  double weight = 0.0;

  bool Evaluate(double const* const* blocks, double* residuals,
                double** jacobians) const;

  static ceres::CostFunction* Create(BalanceCost cost);
};

// Balance on average (blocks: one frame's root position, quaternion and
// hinges): a person's centre of mass stands over their feet on average,
// whatever it does frame by frame. Residuals, 2: weight x (the horizontal
// offset of the centre of mass from the contact-weighted centre of the
// in-contact sole points - target), m. The targets (fit.cc,
// AddMeanBalance) are each frame's own offset less its window's mean
// offset, both from the estimate the solve starts from: each frame keeps
// its sway, and the window's mean moves toward zero. A body leaning toward
// a camera that looks level (how a wrong pitch hides) has its centre of
// mass in front of its feet the whole time. The whole pose enters: held
// in the root's frame, the offset let the solver turn the root and bend
// the hips back, the body's lean unchanged.
struct LeanCost {
  const KinematicModel* model;
  std::vector<double> contact_weights;  // per sole point; some > 0
  double target_m[2] = {0.0, 0.0};
  double weight = 0.0;

  // Residuals and requested Jacobians (analytic: the centre of mass's and
  // the sole points' rows).
  bool Evaluate(double const* const* blocks, double* residuals,
                double** jacobians) const;

  static ceres::CostFunction* Create(LeanCost cost);
};

// weight x (value - prior), element-wise over one block (pose prior: hinge
// angles toward the rest pose's 0).
struct PriorCost {
  int size;
  double weight;

  template <typename T>
  bool operator()(T const* const* blocks, T* residuals) const {
    for (int i = 0; i < size; ++i) residuals[i] = T(weight) * blocks[0][i];
    return true;
  }

  static ceres::CostFunction* Create(int size, double weight) {
    auto* function = new ceres::DynamicAutoDiffCostFunction<PriorCost, 16>(
        new PriorCost{size, weight});
    function->AddParameterBlock(size);
    function->SetNumResiduals(size);
    return function;
  }
};

// weight x (a - 2 b + c) over three consecutive frames' blocks of one size:
// acceleration (hinges, root position, camera centre).
struct AccelerationCost {
  int size;
  double weight;

  template <typename T>
  bool operator()(T const* const* blocks, T* residuals) const {
    for (int i = 0; i < size; ++i) {
      residuals[i] =
          T(weight) * (blocks[0][i] - T(2) * blocks[1][i] + blocks[2][i]);
    }
    return true;
  }

  static ceres::CostFunction* Create(int size, double weight) {
    auto* function =
        new ceres::DynamicAutoDiffCostFunction<AccelerationCost, 16>(
            new AccelerationCost{size, weight});
    for (int k = 0; k < 3; ++k) function->AddParameterBlock(size);
    function->SetNumResiduals(size);
    return function;
  }
};

// weight x (b - a) for two consecutive 3-vectors (a moving camera's speed:
// a weak preference for a still camera, which fixes the split of a shared
// drift between camera and subject until the feet pin the subject).
struct VelocityCost {
  double weight;

  template <typename T>
  bool operator()(const T* a, const T* b, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = T(weight) * (b[i] - a[i]);
    return true;
  }

  static ceres::CostFunction* Create(double weight) {
    return new ceres::AutoDiffCostFunction<VelocityCost, 3, 3, 3>(
        new VelocityCost{weight});
  }
};

// Angular acceleration of the root orientation over three frames: the
// change between consecutive relative rotations (as rotation vectors).
struct TurnAccelerationCost {
  double weight;

  template <typename T>
  static void RelativeRotation(const T* from, const T* to, T* rotation_vector) {
    using std::sqrt;
    T inverse[4] = {from[0], -from[1], -from[2], -from[3]};
    const T norm_from = from[0] * from[0] + from[1] * from[1] +
                        from[2] * from[2] + from[3] * from[3];
    T relative[4];
    ceres::QuaternionProduct(to, inverse, relative);
    const T norm_to =
        to[0] * to[0] + to[1] * to[1] + to[2] * to[2] + to[3] * to[3];
    const T scale = T(1) / sqrt(norm_from * norm_to);
    for (T& value : relative) value *= scale;
    if (relative[0] < T(0))
      for (T& value : relative) value = -value;
    ceres::QuaternionToAngleAxis(relative, rotation_vector);
  }

  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* residuals) const {
    T first[3], second[3];
    RelativeRotation(a, b, first);
    RelativeRotation(b, c, second);
    for (int i = 0; i < 3; ++i)
      residuals[i] = T(weight) * (second[i] - first[i]);
    return true;
  }

  static ceres::CostFunction* Create(double weight) {
    return new ceres::AutoDiffCostFunction<TurnAccelerationCost, 3, 4, 4, 4>(
        new TurnAccelerationCost{weight});
  }
};

// weight x log(value / prior) on one element of a block: the focal length
// (a 1-block), the camera's height (element 2 of its centre).
// A prior on one number of a block: weight x log(value / prior) for a
// positive scale (focal length, height), weight x (value - prior) for a
// quantity that may be zero or negative (an angle).
enum class PriorScale { kLog, kLinear };

template <int kBlockSize, int kIndex, PriorScale kScale>
struct ScalarPriorCost {
  double prior;
  double weight;

  template <typename T>
  bool operator()(const T* block, T* residual) const {
    using std::log;
    residual[0] =
        T(weight) * (kScale == PriorScale::kLog ? log(block[kIndex] / T(prior))
                                                : block[kIndex] - T(prior));
    return true;
  }

  static ceres::CostFunction* Create(double prior, double weight) {
    return new ceres::AutoDiffCostFunction<ScalarPriorCost, 1, kBlockSize>(
        new ScalarPriorCost{prior, weight});
  }
};
using FocalPriorCost = ScalarPriorCost<1, 0, PriorScale::kLog>;
using CameraHeightPriorCost = ScalarPriorCost<3, 2, PriorScale::kLog>;
// On (pitch, roll): roll toward level.
using CameraRollPriorCost = ScalarPriorCost<2, 1, PriorScale::kLinear>;

}  // namespace m2d

#endif  // MIMIC2D_FIT_COSTS_H_
