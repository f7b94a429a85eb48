#include "sim/simulation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "common/error.h"
#include "sim/pose_mapping.h"

namespace m2d {
namespace {

// MuJoCo warnings that mean the state blew up (MuJoCo then resets mjData).
constexpr int kBadStateWarnings[] = {mjWARN_BADQPOS, mjWARN_BADQVEL,
                                     mjWARN_BADQACC};
constexpr int kNumBadStateWarnings = 3;

void CopyInto(std::vector<double>* out, const double* values, int count) {
  out->assign(values, values + count);
}

void CopyFrom(const std::vector<double>& values, double* out, int count,
              const char* field) {
  if (static_cast<int>(values.size()) != count) {
    throw InputError("simulation state", std::string(field) + " has " +
                                             std::to_string(values.size()) +
                                             " values, the model needs " +
                                             std::to_string(count));
  }
  if (count > 0) std::memcpy(out, values.data(), sizeof(double) * count);
}

// PD target for one normalized action: clipped to [-1, 1]; NaN (which would
// poison the state) holds the range centre.
inline double TargetFor(const ActuatedHinge& hinge, float normalized_action) {
  double action = std::clamp(static_cast<double>(normalized_action), -1.0, 1.0);
  if (std::isnan(action)) action = 0.0;
  return hinge.target_mid_rad + action * hinge.target_half_range_rad;
}

}  // namespace

void SimulationOptions::Validate() const { CheckRanges(*this, "env"); }

std::shared_ptr<const Character> LoadCharacterForSimulation(
    const std::string& config_path, const std::string& scene_name,
    const SimulationOptions& options) {
  options.Validate();
  return Character::Load(config_path, scene_name, options.physics_timestep_s());
}

const char* DivergenceName(Divergence divergence) {
  switch (divergence) {
    case Divergence::kNone:
      return "none";
    case Divergence::kNonFinite:
      return "non-finite state";
    case Divergence::kExcessiveSpeed:
      return "excessive speed";
    case Divergence::kBadPhysics:
      return "MuJoCo bad qpos/qvel/qacc";
    case Divergence::kEngineError:
      return "MuJoCo engine error";
  }
  return "unknown";
}

Simulation::Simulation(std::shared_ptr<const Character> character,
                       const SimulationOptions& options)
    : character_(std::move(character)), options_(options) {
  options_.Validate();
  const mjModel* m = character_->model();
  if (std::abs(m->opt.timestep - options_.physics_timestep_s()) > 1e-12) {
    throw ConfigError("the character was loaded with a " +
                      std::to_string(m->opt.timestep) +
                      " s time step; these options need " +
                      std::to_string(options_.physics_timestep_s()) +
                      " s (use LoadCharacterForSimulation)");
  }
  data_ = MakeMujocoData(m);

  // Per-DoF speed limits, so divergence checks are one pass over qvel.
  speed_limit_.assign(m->nv, options_.max_joint_speed_rad_s);
  for (int j = 0; j < m->njnt; ++j) {
    const bool own = character_->IsCharacterBody(m->jnt_bodyid[j]);
    const double spin_limit =
        own ? options_.max_joint_speed_rad_s : options_.max_object_spin_rad_s;
    double* limit = speed_limit_.data() + m->jnt_dofadr[j];
    switch (m->jnt_type[j]) {
      case mjJNT_FREE:
        std::fill(limit, limit + 3, options_.max_linear_speed_m_s);
        std::fill(limit + 3, limit + 6, spin_limit);
        break;
      case mjJNT_BALL:
        std::fill(limit, limit + 3, spin_limit);
        break;
      case mjJNT_SLIDE:
        *limit = options_.max_linear_speed_m_s;
        break;
      case mjJNT_HINGE:
        *limit = spin_limit;
        break;
    }
  }
  hinge_qvel_.assign(character_->num_actions(), 0.0);
  targets_rad_.assign(character_->num_actions(), 0.0);
  mean_torques_.assign(character_->num_actions(), 0.0);
  allowed_ground_.assign(m->nbody, 0);
  for (int body : character_->ground_contact_bodies())
    allowed_ground_[body] = 1;
  Reset();
}

void Simulation::ActionsToTargets(const float* normalized_actions,
                                  double* targets_rad) const {
  const std::vector<ActuatedHinge>& hinges = character_->hinges();
  for (size_t i = 0; i < hinges.size(); ++i) {
    targets_rad[i] = TargetFor(hinges[i], normalized_actions[i]);
  }
}

StepResult Simulation::Step(const float* normalized_actions) {
  // Outline: actions -> servo targets; then per substep: integrate
  // (mj_step2), accumulate PD torque and power, compute the new state's
  // positions/velocities/contacts (mj_step1), check for divergence.
  StepResult result;
  if (diverged()) {
    result.divergence = divergence_;
    return result;
  }
  const mjModel* m = character_->model();
  mjData* d = data_.get();
  const std::vector<ActuatedHinge>& hinges = character_->hinges();
  const int num_hinges = static_cast<int>(hinges.size());
  for (int i = 0; i < num_hinges; ++i) {
    targets_rad_[i] = TargetFor(hinges[i], normalized_actions[i]);
    d->ctrl[hinges[i].actuator_id] = targets_rad_[i];
  }
  const bool limit_whole_pd = options_.torque_limit == TorqueLimit::kPd;
  std::fill(mean_torques_.begin(), mean_torques_.end(), 0.0);
  double power_sum = 0.0;
  int substeps_done = 0;
  try {
    for (int s = 0; s < options_.physics_substeps; ++s) {
      int warnings_before[kNumBadStateWarnings];
      for (int w = 0; w < kNumBadStateWarnings; ++w) {
        warnings_before[w] = d->warning[kBadStateWarnings[w]].number;
      }
      for (int i = 0; i < num_hinges; ++i) {
        hinge_qvel_[i] = d->qvel[hinges[i].dof_address];
      }
      if (limit_whole_pd) LimitWholePd(targets_rad_.data());
      mj_step2(m, d);
      // The forces mj_step2 used: servo (clamped) plus joint damping, plus
      // the damping's cancellation where the whole PD is at its limit.
      for (int i = 0; i < num_hinges; ++i) {
        const int dof = hinges[i].dof_address;
        const double torque = d->qfrc_actuator[dof] + d->qfrc_passive[dof] +
                              (limit_whole_pd ? d->qfrc_applied[dof] : 0.0);
        mean_torques_[i] += torque;
        power_sum += std::abs(hinge_qvel_[i] * torque);
      }
      mj_step1(m, d);
      ++substeps_done;
      CheckDivergence(warnings_before);
      if (diverged()) break;
    }
  } catch (const MujocoError&) {
    mj_resetData(m, d);
    divergence_ = Divergence::kEngineError;
  }
  if (substeps_done > 0) {
    for (double& torque : mean_torques_) torque /= substeps_done;
    result.mean_abs_power_w = power_sum / substeps_done;
  }
  result.divergence = divergence_;
  return result;
}

void Simulation::LimitWholePd(const double* targets_rad) {
  // Per hinge, the PD torque u = kp (q* - q) - kd qdot. The joint's damping
  // (-kd qdot, integrated implicitly: stable at any rate) stays as it is;
  // the servo and an applied torque make up the rest:
  // - u within the limit: the servo's kp (q* - q), plus what its own clamp
  //   cut off (nothing, unless the joint is fast and the target far);
  // - u beyond it: the servo at the limit and kd qdot, cancelling the
  //   damping, so that the joint gets the limit itself, as from a
  //   torque-limited PD (DeepMimic). The implicit damping still weighs the
  //   step's velocity change, as if the joint were h kd heavier then.
  mjData* d = data_.get();
  const std::vector<ActuatedHinge>& hinges = character_->hinges();
  for (size_t i = 0; i < hinges.size(); ++i) {
    const ActuatedHinge& hinge = hinges[i];
    const double q = d->qpos[hinge.qpos_address];
    const double qdot = d->qvel[hinge.dof_address];
    const double servo_nm = hinge.kp_nm_per_rad * (targets_rad[i] - q);
    const double pd_nm = servo_nm - hinge.kd_nm_s_per_rad * qdot;
    double* ctrl = d->ctrl + hinge.actuator_id;
    double* applied = d->qfrc_applied + hinge.dof_address;
    if (pd_nm > hinge.torque_high_nm || pd_nm < hinge.torque_low_nm) {
      // Twice the limit's distance: the servo clamps at exactly the limit.
      const double limit_nm =
          pd_nm > 0.0 ? hinge.torque_high_nm : hinge.torque_low_nm;
      *ctrl = q + 2.0 * limit_nm / hinge.kp_nm_per_rad;
      *applied = hinge.kd_nm_s_per_rad * qdot;
    } else {
      *ctrl = targets_rad[i];
      *applied = servo_nm - std::clamp(servo_nm, hinge.torque_low_nm,
                                       hinge.torque_high_nm);
    }
  }
}

void Simulation::CheckDivergence(const int* warnings_before) {
  const mjModel* m = character_->model();
  const mjData* d = data_.get();
  for (int w = 0; w < kNumBadStateWarnings; ++w) {
    if (d->warning[kBadStateWarnings[w]].number != warnings_before[w]) {
      divergence_ = Divergence::kBadPhysics;
      return;
    }
  }
  for (int i = 0; i < m->nq; ++i) {
    if (!std::isfinite(d->qpos[i])) {
      divergence_ = Divergence::kNonFinite;
      return;
    }
  }
  for (int i = 0; i < m->nv; ++i) {
    // Written so that NaN fails the test too.
    if (!(std::abs(d->qvel[i]) <= speed_limit_[i])) {
      divergence_ = std::isfinite(d->qvel[i]) ? Divergence::kExcessiveSpeed
                                              : Divergence::kNonFinite;
      return;
    }
  }
}

void Simulation::Refresh() {
  mjData* d = data_.get();
  divergence_ = Divergence::kNone;
  int warnings_before[kNumBadStateWarnings];
  for (int w = 0; w < kNumBadStateWarnings; ++w) {
    warnings_before[w] = d->warning[kBadStateWarnings[w]].number;
  }
  try {
    mj_step1(character_->model(), d);
  } catch (const MujocoError&) {
    mj_resetData(character_->model(), d);
    divergence_ = Divergence::kEngineError;
    return;
  }
  CheckDivergence(warnings_before);
}

void Simulation::Reset() {
  mj_resetData(character_->model(), data_.get());
  Refresh();
}

void Simulation::SetPose(const Pose3D& pose, const double* character_qvel) {
  const mjModel* m = character_->model();
  mjData* d = data_.get();
  PoseToQpos(*character_, pose, d->qpos);
  const int root = character_->root_dof_address();
  for (int k = 0; k < 6; ++k) {
    d->qvel[root + k] = character_qvel ? character_qvel[root + k] : 0.0;
  }
  for (const ActuatedHinge& hinge : character_->hinges()) {
    d->qvel[hinge.dof_address] =
        character_qvel ? character_qvel[hinge.dof_address] : 0.0;
  }
  // A new start: no solver history, so episodes do not depend on the past.
  mju_zero(d->qacc_warmstart, m->nv);
  Refresh();
}

SimState Simulation::Save() const {
  SimState state;
  Save(&state);
  return state;
}

void Simulation::Save(SimState* state) const {
  const mjModel* m = character_->model();
  const mjData* d = data_.get();
  state->time_s = d->time;
  CopyInto(&state->qpos, d->qpos, m->nq);
  CopyInto(&state->qvel, d->qvel, m->nv);
  CopyInto(&state->act, d->act, m->na);
  CopyInto(&state->qacc_warmstart, d->qacc_warmstart, m->nv);
  CopyInto(&state->ctrl, d->ctrl, m->nu);
  CopyInto(&state->qfrc_applied, d->qfrc_applied, m->nv);
  CopyInto(&state->xfrc_applied, d->xfrc_applied, 6 * m->nbody);
  CopyInto(&state->mocap_pos, d->mocap_pos, 3 * m->nmocap);
  CopyInto(&state->mocap_quat, d->mocap_quat, 4 * m->nmocap);
}

void Simulation::Restore(const SimState& state) {
  const mjModel* m = character_->model();
  mjData* d = data_.get();
  CopyFrom(state.qpos, d->qpos, m->nq, "qpos");
  CopyFrom(state.qvel, d->qvel, m->nv, "qvel");
  CopyFrom(state.act, d->act, m->na, "act");
  CopyFrom(state.qacc_warmstart, d->qacc_warmstart, m->nv, "qacc_warmstart");
  CopyFrom(state.ctrl, d->ctrl, m->nu, "ctrl");
  CopyFrom(state.qfrc_applied, d->qfrc_applied, m->nv, "qfrc_applied");
  CopyFrom(state.xfrc_applied, d->xfrc_applied, 6 * m->nbody, "xfrc_applied");
  CopyFrom(state.mocap_pos, d->mocap_pos, 3 * m->nmocap, "mocap_pos");
  CopyFrom(state.mocap_quat, d->mocap_quat, 4 * m->nmocap, "mocap_quat");
  d->time = state.time_s;
  Refresh();
}

void Simulation::KeypointPositions(double* out_xyz) const {
  const mjData* d = data_.get();
  for (int site : character_->keypoint_sites()) {
    std::memcpy(out_xyz, d->site_xpos + 3 * site, 3 * sizeof(double));
    out_xyz += 3;
  }
}

bool Simulation::GeomIsGround(int geom) const {
  return character_->model()->geom_bodyid[geom] == 0;
}

bool Simulation::BodyTouchesGround(int body_id) const {
  const mjModel* m = character_->model();
  const mjData* d = data_.get();
  for (int c = 0; c < d->ncon; ++c) {
    const int g1 = d->contact[c].geom1;
    const int g2 = d->contact[c].geom2;
    if ((GeomIsGround(g1) && m->geom_bodyid[g2] == body_id) ||
        (GeomIsGround(g2) && m->geom_bodyid[g1] == body_id)) {
      return true;
    }
  }
  return false;
}

void Simulation::GroundContacts(std::vector<uint8_t>* touching) const {
  const mjModel* m = character_->model();
  const mjData* d = data_.get();
  touching->assign(m->nbody, 0);
  for (int c = 0; c < d->ncon; ++c) {
    const int g1 = d->contact[c].geom1;
    const int g2 = d->contact[c].geom2;
    if (GeomIsGround(g1)) (*touching)[m->geom_bodyid[g2]] = 1;
    if (GeomIsGround(g2)) (*touching)[m->geom_bodyid[g1]] = 1;
  }
}

bool Simulation::UnexpectedGroundContact() const {
  const mjModel* m = character_->model();
  const mjData* d = data_.get();
  for (int c = 0; c < d->ncon; ++c) {
    const int g1 = d->contact[c].geom1;
    const int g2 = d->contact[c].geom2;
    int other = -1;
    if (GeomIsGround(g1)) other = m->geom_bodyid[g2];
    if (GeomIsGround(g2)) other = m->geom_bodyid[g1];
    if (other > 0 && character_->IsCharacterBody(other) &&
        !allowed_ground_[other]) {
      return true;
    }
  }
  return false;
}

std::vector<Eigen::Vector3d> SimulatedKeypoints(const Simulation& simulation) {
  const int count = simulation.character().keypoint_layout().num_keypoints();
  std::vector<double> xyz(3 * count);
  simulation.KeypointPositions(xyz.data());
  std::vector<Eigen::Vector3d> points(count);
  for (int j = 0; j < count; ++j)
    points[j] = {xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]};
  return points;
}

double LowestGeomPointZ(const mjModel* m, const mjData* d, int g) {
  const double* size = m->geom_size + 3 * g;
  // Row 2 of the geom's rotation: the world z of its local axes.
  const double* z_of_axis = d->geom_xmat + 9 * g + 6;
  const double axis_z = std::abs(z_of_axis[2]);
  double reach_m = m->geom_rbound[g];
  switch (m->geom_type[g]) {
    case mjGEOM_SPHERE:
      reach_m = size[0];
      break;
    case mjGEOM_CAPSULE:
      reach_m = size[0] + size[1] * axis_z;
      break;
    case mjGEOM_CYLINDER:
      reach_m = size[0] * std::sqrt(std::max(0.0, 1.0 - axis_z * axis_z)) +
                size[1] * axis_z;
      break;
    case mjGEOM_BOX:
      reach_m = size[0] * std::abs(z_of_axis[0]) +
                size[1] * std::abs(z_of_axis[1]) + size[2] * axis_z;
      break;
    default:
      break;
  }
  return d->geom_xpos[3 * g + 2] - reach_m;
}

double LowestCharacterPointZ(const Simulation& simulation) {
  const mjModel* m = simulation.model();
  const mjData* d = simulation.data();
  double lowest_m = std::numeric_limits<double>::infinity();
  for (int g = 0; g < m->ngeom; ++g) {
    if (!simulation.character().IsCharacterBody(m->geom_bodyid[g])) continue;
    if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) continue;
    lowest_m = std::min(lowest_m, LowestGeomPointZ(m, d, g));
  }
  return lowest_m;
}

}  // namespace m2d
