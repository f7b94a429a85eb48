#include "fit/kinematics.h"

#include <ceres/jet.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "sim/character.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

// The four lowest corners (in the body frame) of every box geom of `body`.
std::vector<Eigen::Vector3d> SoleCorners(const mjModel* model, int body) {
  std::vector<Eigen::Vector3d> corners;
  for (int g = 0; g < model->ngeom; ++g) {
    if (model->geom_bodyid[g] != body || model->geom_type[g] != mjGEOM_BOX)
      continue;
    const Eigen::Vector3d centre(model->geom_pos + 3 * g);
    const mjtNum* q = model->geom_quat + 4 * g;
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    const Eigen::Vector3d size(model->geom_size + 3 * g);
    std::vector<Eigen::Vector3d> box;
    for (int sx : {-1, 1})
      for (int sy : {-1, 1})
        for (int sz : {-1, 1}) {
          box.push_back(centre + rotation * Eigen::Vector3d(sx * size.x(),
                                                            sy * size.y(),
                                                            sz * size.z()));
        }
    std::sort(box.begin(), box.end(),
              [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                return a.z() < b.z();
              });
    corners.insert(corners.end(), box.begin(), box.begin() + 4);
  }
  return corners;
}

}  // namespace

namespace {

// One pose's joint frames and what every point's pose Jacobian needs: each
// hinge's world axis (its sign folded in), the rotation's derivatives in the
// quaternion, and which joint carries the quaternion.
class PoseJacobianContext {
 public:
  PoseJacobianContext(const KinematicModel& model,
                      const double* root_position_m,
                      const double* root_quaternion_wxyz,
                      const double* hinges_rad)
      : model_(model), hinge_axis_(model.num_hinges()) {
    using Eigen::Matrix3d;
    using Eigen::Vector3d;
    JointFrames(model, root_position_m, root_quaternion_wxyz, hinges_rad,
                orientation_, position_);
    const int num_joints = static_cast<int>(model.joints.size());
    for (int j = 0; j < num_joints; ++j) {
      const KinematicModel::Joint& joint = model.joints[j];
      const Matrix3d parent =
          joint.parent < 0 ? Matrix3d::Identity() : orientation_[joint.parent];
      if (joint.type == JointType::kSpherical) {
        // Rx(a) Ry(b) Rz(c): each axis as the preceding rotations leave it.
        const double* angles = hinges_rad + joint.first_hinge;
        const Matrix3d rx =
            fk_internal::AxisRotation<double>(Vector3d::UnitX(), angles[0]);
        const Matrix3d ry =
            fk_internal::AxisRotation<double>(Vector3d::UnitY(), angles[1]);
        hinge_axis_[joint.first_hinge] = parent.col(0);
        hinge_axis_[joint.first_hinge + 1] = parent * rx.col(1);
        hinge_axis_[joint.first_hinge + 2] = parent * (rx * ry).col(2);
      } else if (joint.type == JointType::kRevolute) {
        hinge_axis_[joint.first_hinge] =
            joint.revolute_sign * (parent * joint.axis);
      }
      if (joint.type == JointType::kFree) free_joint_ = j;
    }
    Jet4 quaternion[4];
    for (int k = 0; k < 4; ++k)
      quaternion[k] = Jet4(root_quaternion_wxyz[k], k);
    ceres::QuaternionToRotation(quaternion, rotation_);
  }

  // `point`'s world position, and `scale` x its 3 pose Jacobian rows added
  // into `rows` (PoseJacobianColumns wide each).
  Eigen::Vector3d AddPoint(const BodyPoint& point, double scale,
                           double* const rows[3]) const {
    using Eigen::Vector3d;
    const Vector3d world =
        position_[point.joint] + orientation_[point.joint] * point.offset_m;
    for (int c = 0; c < 3; ++c) rows[c][c] += scale;
    if (free_joint_ >= 0) {
      const Vector3d in_root = orientation_[free_joint_].transpose() *
                               (world - position_[free_joint_]);
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 4; ++k) {
          rows[c][kRootPositionSize + k] +=
              scale * (rotation_[3 * c].v[k] * in_root[0] +
                       rotation_[3 * c + 1].v[k] * in_root[1] +
                       rotation_[3 * c + 2].v[k] * in_root[2]);
        }
    }
    constexpr int kFirstHingeColumn = kRootPositionSize + kRootQuaternionSize;
    for (int j = point.joint; j >= 0; j = model_.joints[j].parent) {
      const KinematicModel::Joint& joint = model_.joints[j];
      const int dofs = joint.num_hinges();
      const Vector3d lever = world - position_[j];
      for (int d = 0; d < dofs; ++d) {
        const int hinge = joint.first_hinge + d;
        const Vector3d moved = hinge_axis_[hinge].cross(lever);
        for (int c = 0; c < 3; ++c)
          rows[c][kFirstHingeColumn + hinge] += scale * moved[c];
      }
    }
    return world;
  }

 private:
  using Jet4 = ceres::Jet<double, 4>;
  const KinematicModel& model_;
  Eigen::Matrix3d orientation_[kMaxFitJoints];
  Eigen::Vector3d position_[kMaxFitJoints];
  std::vector<Eigen::Vector3d> hinge_axis_;
  Jet4 rotation_[9];  // row-major, with d/dq_k
  int free_joint_ = -1;
};

// Spheres along a segment from `a` to `b` (joint frame, m) of `radius_m`,
// spaced at most one radius apart, both ends included: their union is the
// capsule's to within 14 % of its radius at the waist between two spheres.
void AddSphereRow(int joint, int geom, const Eigen::Vector3d& a,
                  const Eigen::Vector3d& b, double radius_m,
                  std::vector<CollisionSphere>* spheres) {
  const double length_m = (b - a).norm();
  const int count =
      1 + static_cast<int>(std::ceil(length_m / std::max(radius_m, 1e-6)));
  for (int i = 0; i < count; ++i) {
    const double s = count == 1 ? 0.5 : static_cast<double>(i) / (count - 1);
    spheres->push_back({{joint, a + s * (b - a)}, radius_m, geom});
  }
}

// Whether MuJoCo's collision filter lets bodies `b1` and `b2` of `m` touch
// through geoms `g1` and `g2`: contype/conaffinity, no parent-child pair
// (filterparent), no <exclude>.
bool MayCollide(const mjModel* m, int g1, int g2) {
  const int b1 = m->geom_bodyid[g1], b2 = m->geom_bodyid[g2];
  if (b1 == b2) return false;
  if (!((m->geom_contype[g1] & m->geom_conaffinity[g2]) ||
        (m->geom_contype[g2] & m->geom_conaffinity[g1]))) {
    return false;
  }
  const bool filter_parent = !(m->opt.disableflags & mjDSBL_FILTERPARENT);
  if (filter_parent && ((m->body_parentid[b1] == b2 && b2 != 0) ||
                        (m->body_parentid[b2] == b1 && b1 != 0))) {
    return false;
  }
  const int signature = (std::min(b1, b2) << 16) + std::max(b1, b2);
  for (int e = 0; e < m->nexclude; ++e) {
    if (m->exclude_signature[e] == signature) return false;
  }
  return true;
}

// The character's collision geoms as spheres in their joints' frames, and
// the pairs of them that may collide and are apart at rest. Spheres are
// one sphere; capsules and boxes a row along their long axis (a box's
// radius its smaller cross half-size); other shapes are left out.
void AddCollisionSpheres(const Character& character, KinematicModel* model) {
  const mjModel* m = character.model();
  const Skeleton& skeleton = character.skeleton();
  for (int g = 0; g < m->ngeom; ++g) {
    const int body = m->geom_bodyid[g];
    if (!character.IsCharacterBody(body)) continue;
    if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) continue;
    int joint = -1;
    for (int j = 0; j < skeleton.num_joints(); ++j) {
      if (character.joints()[j].body_id == body) joint = j;
    }
    if (joint < 0) continue;
    const Eigen::Vector3d centre(m->geom_pos + 3 * g);
    const Eigen::Matrix3d axes =
        Eigen::Quaterniond(m->geom_quat[4 * g], m->geom_quat[4 * g + 1],
                           m->geom_quat[4 * g + 2], m->geom_quat[4 * g + 3])
            .normalized()
            .toRotationMatrix();
    const double* size = m->geom_size + 3 * g;
    switch (m->geom_type[g]) {
      case mjGEOM_SPHERE:
        model->collision_spheres.push_back({{joint, centre}, size[0], g});
        break;
      case mjGEOM_CAPSULE: {
        const Eigen::Vector3d half = size[1] * axes.col(2);
        AddSphereRow(joint, g, centre - half, centre + half, size[0],
                     &model->collision_spheres);
        break;
      }
      case mjGEOM_BOX: {
        int longest = 0;
        for (int k = 1; k < 3; ++k)
          if (size[k] > size[longest]) longest = k;
        const double radius_m =
            std::min(size[(longest + 1) % 3], size[(longest + 2) % 3]);
        const Eigen::Vector3d half =
            std::max(0.0, size[longest] - radius_m) * axes.col(longest);
        AddSphereRow(joint, g, centre - half, centre + half, radius_m,
                     &model->collision_spheres);
        break;
      }
      default:
        break;
    }
  }
  // The rest pose (hinges at 0, clamped into their ranges) decides which
  // pairs are apart by design: those that touch there are neighbours.
  std::vector<double> rest(model->num_hinges());
  for (int h = 0; h < model->num_hinges(); ++h)
    rest[h] =
        std::clamp(0.0, model->hinge_low_rad[h], model->hinge_high_rad[h]);
  const double origin[3] = {0, 0, 0};
  const double identity[4] = {1, 0, 0, 0};
  const std::vector<double> at_rest =
      CollisionSphereCentres(*model, origin, identity, rest.data());
  const int num_spheres = static_cast<int>(model->collision_spheres.size());
  for (int a = 0; a < num_spheres; ++a) {
    for (int b = a + 1; b < num_spheres; ++b) {
      if (!MayCollide(m, model->collision_spheres[a].geom,
                      model->collision_spheres[b].geom) ||
          SphereGapM(*model, at_rest, a, b) <= 0.0) {
        continue;
      }
      model->collision_pairs.push_back({a, b});
    }
  }
}

}  // namespace

std::vector<char> JointsMovedBy(const KinematicModel& model,
                                const std::vector<int>& hinges) {
  const int num_joints = static_cast<int>(model.joints.size());
  std::vector<char> moves(num_joints, 0);
  for (int j = 0; j < num_joints; ++j) {
    const KinematicModel::Joint& joint = model.joints[j];
    for (int h : hinges) {
      if (h >= joint.first_hinge && h < joint.first_hinge + joint.num_hinges())
        moves[j] = 1;
    }
    if (joint.parent >= 0 && moves[joint.parent]) moves[j] = 1;
  }
  return moves;
}

void CharacterPointsWithJacobian(const KinematicModel& model,
                                 const double* root_position_m,
                                 const double* root_quaternion_wxyz,
                                 const double* hinges_rad, double* points_m,
                                 double* jacobian) {
  // Outline: the joint frames, hinge axes and dR/dq once; then per point
  // its position and one Jacobian row block: identity for the root
  // position, dR/dq u for the quaternion, axis x (point - pivot) for every
  // hinge of the joints above it.
  const PoseJacobianContext context(model, root_position_m,
                                    root_quaternion_wxyz, hinges_rad);
  const int columns = PoseJacobianColumns(model);
  const int num_points = model.num_keypoints() + model.num_sole_points();
  std::fill(jacobian, jacobian + 3 * num_points * columns, 0.0);
  int row = 0;
  for (const std::vector<BodyPoint>* points :
       {&model.keypoints, &model.sole_points}) {
    for (const BodyPoint& point : *points) {
      double* const rows[3] = {jacobian + row * columns,
                               jacobian + (row + 1) * columns,
                               jacobian + (row + 2) * columns};
      const Eigen::Vector3d world = context.AddPoint(point, 1.0, rows);
      for (int c = 0; c < 3; ++c) points_m[row + c] = world[c];
      row += 3;
    }
  }
}

void BodyPointsWithJacobian(const KinematicModel& model,
                            const double* root_position_m,
                            const double* root_quaternion_wxyz,
                            const double* hinges_rad,
                            const std::vector<BodyPoint>& points,
                            double* points_m, double* jacobian) {
  if (jacobian == nullptr) {
    Eigen::Matrix3d orientation[kMaxFitJoints];
    Eigen::Vector3d position[kMaxFitJoints];
    JointFrames(model, root_position_m, root_quaternion_wxyz, hinges_rad,
                orientation, position);
    for (size_t p = 0; p < points.size(); ++p) {
      const Eigen::Vector3d world =
          position[points[p].joint] +
          orientation[points[p].joint] * points[p].offset_m;
      for (int c = 0; c < 3; ++c) points_m[3 * p + c] = world[c];
    }
    return;
  }
  const PoseJacobianContext context(model, root_position_m,
                                    root_quaternion_wxyz, hinges_rad);
  const int columns = PoseJacobianColumns(model);
  std::fill(jacobian, jacobian + 3 * points.size() * columns, 0.0);
  for (size_t p = 0; p < points.size(); ++p) {
    double* const rows[3] = {jacobian + 3 * p * columns,
                             jacobian + (3 * p + 1) * columns,
                             jacobian + (3 * p + 2) * columns};
    const Eigen::Vector3d world = context.AddPoint(points[p], 1.0, rows);
    for (int c = 0; c < 3; ++c) points_m[3 * p + c] = world[c];
  }
}

std::vector<double> CollisionSphereCentres(const KinematicModel& model,
                                           const double* root_position_m,
                                           const double* root_quaternion_wxyz,
                                           const double* hinges_rad) {
  std::vector<BodyPoint> centres;
  for (const CollisionSphere& sphere : model.collision_spheres)
    centres.push_back(sphere.centre);
  std::vector<double> centres_m(3 * centres.size());
  BodyPointsWithJacobian(model, root_position_m, root_quaternion_wxyz,
                         hinges_rad, centres, centres_m.data(), nullptr);
  return centres_m;
}

double SphereGapM(const KinematicModel& model,
                  const std::vector<double>& centres_m, int a, int b) {
  return (Eigen::Map<const Eigen::Vector3d>(&centres_m[3 * a]) -
          Eigen::Map<const Eigen::Vector3d>(&centres_m[3 * b]))
             .norm() -
         model.collision_spheres[a].radius_m -
         model.collision_spheres[b].radius_m;
}

void CenterOfMassWithJacobian(const KinematicModel& model,
                              const double* root_position_m,
                              const double* root_quaternion_wxyz,
                              const double* hinges_rad, double* com_m,
                              double* jacobian) {
  // Outline: the mass-weighted sum of the bodies' centres and of their
  // Jacobian rows (without a Jacobian, of the centres alone).
  if (jacobian == nullptr) {
    Eigen::Matrix3d orientation[kMaxFitJoints];
    Eigen::Vector3d position[kMaxFitJoints];
    JointFrames(model, root_position_m, root_quaternion_wxyz, hinges_rad,
                orientation, position);
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    for (size_t b = 0; b < model.mass_points.size(); ++b) {
      const BodyPoint& point = model.mass_points[b];
      com +=
          model.mass_fractions[b] *
          (position[point.joint] + orientation[point.joint] * point.offset_m);
    }
    for (int c = 0; c < 3; ++c) com_m[c] = com[c];
    return;
  }
  const PoseJacobianContext context(model, root_position_m,
                                    root_quaternion_wxyz, hinges_rad);
  const int columns = PoseJacobianColumns(model);
  std::fill(jacobian, jacobian + 3 * columns, 0.0);
  double* const rows[3] = {jacobian, jacobian + columns,
                           jacobian + 2 * columns};
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  for (size_t b = 0; b < model.mass_points.size(); ++b) {
    com +=
        model.mass_fractions[b] *
        context.AddPoint(model.mass_points[b], model.mass_fractions[b], rows);
  }
  for (int c = 0; c < 3; ++c) com_m[c] = com[c];
}

KinematicModel KinematicModel::FromCharacter(const Character& character) {
  const Skeleton& skeleton = character.skeleton();
  const mjModel* mj_model = character.model();
  KinematicModel model;
  model.skeleton_name = skeleton.name;
  if (skeleton.num_joints() > kMaxFitJoints) {
    throw InputError(character.config().source_path,
                     "the fit handles skeletons of up to 64 joints");
  }
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const SkeletonJoint& source = skeleton.joints[j];
    const BoundJoint& bound = character.joints()[j];
    Joint joint;
    joint.parent = source.parent;
    joint.type = bound.type;
    joint.offset_m = source.offset_m;
    joint.axis = source.axis;
    joint.first_hinge = bound.first_hinge;
    joint.revolute_sign = bound.revolute_sign;
    model.joints.push_back(joint);
  }
  for (const KeypointAnchor& anchor : character.keypoint_map().anchors)
    model.keypoints.push_back({anchor.joint, anchor.offset_m});
  for (const ActuatedHinge& hinge : character.hinges()) {
    model.hinge_low_rad.push_back(hinge.range_low_rad);
    model.hinge_high_rad.push_back(hinge.range_high_rad);
  }
  // Mass points: each joint's body's centre of mass (MuJoCo's body_ipos, in
  // the body frame, which is the joint's) and its share of the total mass.
  double total_mass_kg = 0.0;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const int body = character.joints()[j].body_id;
    bool seen = false;
    for (const BodyPoint& point : model.mass_points)
      seen = seen || character.joints()[point.joint].body_id == body;
    if (body <= 0 || seen || mj_model->body_mass[body] <= 0.0) continue;
    model.mass_points.push_back(
        {j, Eigen::Vector3d(mj_model->body_ipos + 3 * body)});
    model.mass_fractions.push_back(mj_model->body_mass[body]);
    total_mass_kg += mj_model->body_mass[body];
  }
  if (total_mass_kg <= 0.0) {
    throw InputError(character.config().source_path,
                     "the character's bodies have no mass: the fit's balance "
                     "term needs their centres of mass");
  }
  for (double& fraction : model.mass_fractions) fraction /= total_mass_kg;
  // Sole points: a ground-contact body is the body of some skeleton joint;
  // its box geoms' lowest corners are where it meets the floor.
  for (int body : character.ground_contact_bodies()) {
    int joint = -1;
    for (int j = 0; j < skeleton.num_joints(); ++j) {
      if (character.joints()[j].body_id == body) joint = j;
    }
    if (joint < 0) continue;
    const std::vector<Eigen::Vector3d> corners = SoleCorners(mj_model, body);
    for (const Eigen::Vector3d& corner : corners) {
      model.sole_points.push_back({joint, corner});
      model.sole_foot.push_back(model.num_feet);
    }
    if (!corners.empty()) ++model.num_feet;
  }
  if (model.num_keypoints() + model.num_sole_points() > kMaxFitPoints) {
    throw InputError(character.config().source_path,
                     "the fit handles up to 128 keypoints and sole points");
  }
  if (model.num_feet == 0) {
    throw InputError(character.config().source_path,
                     "no ground-contact body has a box geom: the fit needs "
                     "the soles to put the character on the floor");
  }
  // Standing height: the rest pose with its root at z = 0 has its lowest
  // sole point at -height.
  const double origin[3] = {0, 0, 0};
  const double identity[4] = {1, 0, 0, 0};
  std::vector<double> zeros(model.num_hinges(), 0.0);
  std::vector<double> points(3 *
                             (model.num_keypoints() + model.num_sole_points()));
  CharacterPoints(model, origin, identity, zeros.data(), points.data());
  double lowest_m = 0.0;
  for (int s = 0; s < model.num_sole_points(); ++s) {
    lowest_m = std::min(lowest_m, points[3 * (model.num_keypoints() + s) + 2]);
  }
  model.standing_root_height_m = -lowest_m;
  AddCollisionSpheres(character, &model);
  return model;
}

Pose3D FittedPose(const Character& character, const double* root_position_m,
                  const double* root_quaternion_wxyz,
                  const double* hinges_rad) {
  const mjModel* model = character.model();
  std::vector<double> qpos(model->qpos0, model->qpos0 + model->nq);
  double* root = qpos.data() + character.root_qpos_address();
  Eigen::Vector4d q(root_quaternion_wxyz[0], root_quaternion_wxyz[1],
                    root_quaternion_wxyz[2], root_quaternion_wxyz[3]);
  q.normalize();
  for (int k = 0; k < 3; ++k) root[k] = root_position_m[k];
  for (int k = 0; k < 4; ++k) root[3 + k] = q[k];
  for (size_t h = 0; h < character.hinges().size(); ++h)
    qpos[character.hinges()[h].qpos_address] = hinges_rad[h];
  return QposToPose(character, qpos.data());
}

std::vector<Limb> FindLimbs(const KinematicModel& model) {
  const int num_joints = static_cast<int>(model.joints.size());
  std::vector<int> num_children(num_joints, 0);
  for (const auto& joint : model.joints)
    if (joint.parent >= 0) ++num_children[joint.parent];
  auto is_chain_from = [&](int root) {
    for (int j = root; j < num_joints; ++j) {
      int a = j;
      while (a >= 0 && a != root) a = model.joints[a].parent;
      if (a == root && num_children[j] > 1) return false;
    }
    return true;
  };
  auto in_subtree = [&](int joint, int root) {
    for (int a = joint; a >= 0; a = model.joints[a].parent)
      if (a == root) return true;
    return false;
  };
  std::vector<Limb> limbs;
  for (int root = 0; root < num_joints; ++root) {
    const int parent = model.joints[root].parent;
    if (parent < 0 || num_children[parent] < 2 || !is_chain_from(root))
      continue;
    Limb limb;
    // Joints that move some keypoint of the chain: strict ancestors of a
    // keypoint's joint, or its own joint when the point is off its centre.
    std::vector<char> moves(num_joints, 0);
    for (int k = 0; k < model.num_keypoints(); ++k) {
      const BodyPoint& point = model.keypoints[k];
      if (!in_subtree(point.joint, root)) continue;
      bool moved = false;  // a keypoint at its limb's root stays put
      for (int a = point.joint; a >= 0; a = model.joints[a].parent) {
        if (a != point.joint || point.offset_m.norm() > 1e-6) {
          moves[a] = 1;
          moved = true;
        }
        if (a == root) break;
      }
      if (moved) limb.keypoints.push_back(k);
    }
    // Each moving joint's hinges and the values its starts take. The grid
    // spans the two moving joints nearest the trunk (shoulder and elbow, hip
    // and knee); deeper ones (a quadruped's wrist and paw) start at rest, or
    // the grid would grow as the product of every joint's (1 458 starts a
    // frame for the dog's foreleg, against 18 for the two).
    std::vector<std::vector<double>> axis_values;
    int gridded_joints = 0;
    for (int j = root; j < num_joints; ++j) {
      const auto& joint = model.joints[j];
      if (!moves[j] || joint.first_hinge < 0 || !in_subtree(j, root)) continue;
      const bool gridded = gridded_joints++ < kLimbGridJoints;
      const int size = joint.num_hinges();
      for (int i = 0; i < size; ++i) {
        const int h = joint.first_hinge + i;
        const double low = model.hinge_low_rad[h],
                     high = model.hinge_high_rad[h];
        const double rest = std::clamp(0.0, low, high);
        std::vector<double> values{rest};
        if (gridded && size == 1) {
          values.push_back(0.6 * (std::abs(low) > std::abs(high) ? low : high));
        } else if (gridded && i < 2) {
          values.push_back(0.6 * low);
          values.push_back(0.6 * high);
        }
        limb.hinges.push_back(h);
        axis_values.push_back(values);
      }
    }
    if (limb.hinges.empty() || limb.keypoints.empty()) continue;
    limb.starts.push_back({});
    for (const auto& values : axis_values) {
      std::vector<std::vector<double>> grown;
      for (const auto& start : limb.starts) {
        for (double value : values) {
          grown.push_back(start);
          grown.back().push_back(value);
        }
      }
      limb.starts = std::move(grown);
    }
    limbs.push_back(std::move(limb));
  }
  return limbs;
}

}  // namespace m2d
