#include "eval/motion_feasibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.h"
#include "fit/kinematics.h"
#include "fit/retarget.h"
#include "sim/mujoco_handles.h"
#include "sim/pose_mapping.h"
#include "sim/simulation.h"

namespace m2d {

void FeasibilityOptions::Validate() const {
  if (!(contact_height_m >= 0.0)) {
    throw ConfigError("feasibility contact_height_m must be >= 0 m");
  }
  if (!(friction_coefficient >= 0.0)) {
    throw ConfigError("feasibility friction_coefficient must be >= 0");
  }
  if (!(force_tolerance_body_weights >= 0.0)) {
    throw ConfigError("feasibility force_tolerance_body_weights must be >= 0");
  }
  if (!(range_tolerance_rad >= 0.0)) {
    throw ConfigError("feasibility range_tolerance_rad must be >= 0 rad");
  }
  if (!(reach_tolerance_m >= 0.0)) {
    throw ConfigError("feasibility reach_tolerance_m must be >= 0 m");
  }
  if (!(penetration_tolerance_m >= 0.0)) {
    throw ConfigError("feasibility penetration_tolerance_m must be >= 0 m");
  }
}

int MotionFeasibility::FramesOverTorqueLimit() const {
  return static_cast<int>(std::count_if(
      frames.begin(), frames.end(),
      [](const FrameDemand& f) { return f.worst_torque_ratio > 1.0; }));
}

int MotionFeasibility::FramesOutOfRange() const {
  const double tolerance_rad = range_tolerance_rad;
  return static_cast<int>(std::count_if(
      frames.begin(), frames.end(), [tolerance_rad](const FrameDemand& f) {
        return f.worst_range_excess_rad > tolerance_rad;
      }));
}

int MotionFeasibility::FramesOutOfReach() const {
  const double tolerance_m = reach_tolerance_m;
  return static_cast<int>(std::count_if(frames.begin(), frames.end(),
                                        [tolerance_m](const FrameDemand& f) {
                                          return f.reach_error_m > tolerance_m;
                                        }));
}

double MotionFeasibility::WorstReachErrorM() const {
  double worst_m = 0.0;
  for (const FrameDemand& frame : frames)
    worst_m = std::max(worst_m, frame.reach_error_m);
  return worst_m;
}

int MotionFeasibility::FramesSelfPenetrating() const {
  const double tolerance_m = penetration_tolerance_m;
  return static_cast<int>(std::count_if(
      frames.begin(), frames.end(), [tolerance_m](const FrameDemand& f) {
        return f.self_penetration_m > tolerance_m;
      }));
}

const FrameDemand* MotionFeasibility::DeepestSelfPenetration() const {
  const FrameDemand* deepest = nullptr;
  for (const FrameDemand& frame : frames) {
    if (frame.self_penetration_m <= 0.0) continue;
    if (!deepest || frame.self_penetration_m > deepest->self_penetration_m)
      deepest = &frame;
  }
  return deepest;
}

int MotionFeasibility::FramesFloorCannotExplain() const {
  return static_cast<int>(
      std::count_if(frames.begin(), frames.end(), [](const FrameDemand& f) {
        return f.force_in_flight || f.pulls_floor || f.slips;
      }));
}

int MotionFeasibility::AirborneFrames() const {
  return static_cast<int>(
      std::count_if(frames.begin(), frames.end(),
                    [](const FrameDemand& f) { return !f.touching; }));
}

double MotionFeasibility::MeanForceInFlightBodyWeights() const {
  double sum_n = 0.0;
  int count = 0;
  for (const FrameDemand& frame : frames) {
    if (frame.touching) continue;
    sum_n += frame.external_force_n.norm();
    ++count;
  }
  return count == 0 || body_weight_n <= 0.0 ? 0.0
                                            : sum_n / count / body_weight_n;
}

const HingeDemand* MotionFeasibility::WorstHinge() const {
  const HingeDemand* worst = nullptr;
  for (const HingeDemand& hinge : hinges) {
    if (hinge.frames_measured == 0) continue;
    if (!worst || hinge.peak_ratio > worst->peak_ratio) worst = &hinge;
  }
  return worst;
}

const HingeDemand* MotionFeasibility::WorstRangeHinge() const {
  const HingeDemand* worst = nullptr;
  for (const HingeDemand& hinge : hinges) {
    if (hinge.peak_range_excess_rad <= 0.0) continue;
    if (!worst || hinge.peak_range_excess_rad > worst->peak_range_excess_rad) {
      worst = &hinge;
    }
  }
  return worst;
}

std::string MotionFeasibility::BriefReport() const {
  int pulls = 0, slips = 0, in_flight = 0;
  for (const FrameDemand& frame : frames) {
    pulls += frame.pulls_floor;
    slips += frame.slips;
    in_flight += frame.force_in_flight;
  }
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  out << num_frames << " frames at " << fps << " Hz, body weight "
      << body_weight_n << " N\n";
  out << "  over a torque limit: " << FramesOverTorqueLimit() << " frames\n";
  out << "  out of a joint range: " << FramesOutOfRange() << " frames";
  if (const HingeDemand* worst = WorstRangeHinge()) {
    out << " (furthest " << worst->actuator << " "
        << worst->peak_range_excess_rad * 180.0 / M_PI << " deg, frame "
        << worst->peak_range_frame << ", " << worst->frames_out_of_range
        << " frames)";
  }
  out << "\n";
  out << "  out of reach within the ranges: " << FramesOutOfReach()
      << " frames (a body keypoint more than " << reach_tolerance_m
      << " m off; worst " << WorstReachErrorM() << " m)\n";
  out << "  self-penetrating: " << FramesSelfPenetrating() << " frames";
  if (const FrameDemand* deepest = DeepestSelfPenetration()) {
    out << " (deepest " << deepest->self_contact << " "
        << deepest->self_penetration_m << " m, frame "
        << deepest - frames.data() << ")";
  }
  out << "\n";
  out << "  the floor cannot explain: " << FramesFloorCannotExplain()
      << " frames (" << in_flight << " force in flight, " << pulls << " pull, "
      << slips << " slip); airborne " << AirborneFrames()
      << ", mean force then " << MeanForceInFlightBodyWeights()
      << " body weights\n";
  // The three hinges nearest or furthest past their limits.
  std::vector<const HingeDemand*> by_ratio;
  for (const HingeDemand& hinge : hinges) {
    if (hinge.frames_measured > 0) by_ratio.push_back(&hinge);
  }
  std::sort(by_ratio.begin(), by_ratio.end(),
            [](const HingeDemand* a, const HingeDemand* b) {
              return a->peak_ratio > b->peak_ratio;
            });
  out << "  peak demand / limit:";
  for (size_t i = 0; i < std::min<size_t>(3, by_ratio.size()); ++i) {
    const HingeDemand& hinge = *by_ratio[i];
    out << (i == 0 ? " " : ", ") << hinge.actuator << " " << hinge.peak_ratio
        << " (frame " << hinge.peak_frame << ", " << hinge.frames_over_limit
        << " of " << hinge.frames_measured << " over)";
  }
  out << "\n";
  return out.str();
}

namespace {

// The hinge's torque limit in the direction of `torque_nm` (N m, > 0).
double TorqueLimitNm(const ActuatedHinge& hinge, double torque_nm) {
  return torque_nm >= 0.0 ? hinge.torque_high_nm : -hinge.torque_low_nm;
}

// Per body: whether it or a body below it is within `height_m` of the floor
// (the floor's push then reaches the hinges above it).
std::vector<char> BodiesAboveAContact(const Character& character,
                                      const mjModel* m, const mjData* d,
                                      double height_m, bool* touching) {
  std::vector<char> above(m->nbody, 0);
  *touching = false;
  for (int g = 0; g < m->ngeom; ++g) {
    const int body = m->geom_bodyid[g];
    if (!character.IsCharacterBody(body)) continue;
    if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) continue;
    if (LowestGeomPointZ(m, d, g) >= height_m) continue;
    *touching = true;
    for (int b = body; b > 0 && !above[b]; b = m->body_parentid[b]) {
      above[b] = 1;
    }
  }
  return above;
}

// Per frame, how far the nearest pose within the joint ranges leaves a body
// keypoint: the pose's own keypoints (its angles as they are: MuJoCo's
// kinematics ignores ranges), fitted by in-range hinges from the frame's
// range-nearest angles clamped. Frames already within the ranges are 0.
void MeasureReach(const Character& character, const std::vector<Pose3D>& poses,
                  MotionFeasibility* result) {
  const KinematicModel model = KinematicModel::FromCharacter(character);
  const int num_hinges = model.num_hinges();
  std::vector<double> qpos(character.model()->nq);
  std::vector<double> points(3 * model.num_keypoints());
  std::vector<std::vector<Eigen::Vector3d>> keypoints_m;
  std::vector<Eigen::VectorXd> starts_rad;
  std::vector<int> frames_to_fit;
  for (size_t t = 0; t < poses.size(); ++t) {
    if (result->frames[t].worst_range_excess_rad <= 0.0) continue;
    PoseToQpos(character, poses[t], qpos.data());
    Eigen::VectorXd hinges(num_hinges);
    for (int h = 0; h < num_hinges; ++h)
      hinges[h] = qpos[character.hinges()[h].qpos_address];
    const double* root = qpos.data() + character.root_qpos_address();
    BodyPointsWithJacobian(model, root, root + 3, hinges.data(),
                           model.keypoints, points.data(), nullptr);
    std::vector<Eigen::Vector3d> frame_points;
    for (int j = 0; j < model.num_keypoints(); ++j)
      frame_points.emplace_back(points[3 * j], points[3 * j + 1],
                                points[3 * j + 2]);
    keypoints_m.push_back(std::move(frame_points));
    starts_rad.push_back(hinges);
    frames_to_fit.push_back(static_cast<int>(t));
  }
  if (frames_to_fit.empty()) return;
  // Each frame on its own: no pull toward rest or the previous frame.
  RetargetOptions options;
  options.rest_weight = 0.0;
  options.continuity_weight = 0.0;
  options.max_iterations = 100;
  RetargetSummary summary;
  RetargetKeypointsToHinges(character, keypoints_m, options, "feasibility",
                            &summary, &starts_rad);
  for (size_t i = 0; i < frames_to_fit.size(); ++i) {
    result->frames[frames_to_fit[i]].reach_error_m =
        summary.frame_worst_error_m[i];
  }
}

// Per frame, the deepest overlap between two of the character's own geoms
// (collision detection on the character's model as simulated: its contype,
// conaffinity and parent-child exclusions decide which pairs can touch).
void MeasureSelfPenetration(const Character& character,
                            const std::vector<std::vector<double>>& qpos,
                            MotionFeasibility* result) {
  const mjModel* m = character.model();
  MujocoDataPtr data = MakeMujocoData(m);
  mjData* d = data.get();
  for (size_t t = 0; t < qpos.size(); ++t) {
    std::copy(qpos[t].begin(), qpos[t].end(), d->qpos);
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_collision(m, d);
    FrameDemand& frame = result->frames[t];
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& contact = d->contact[c];
      const int body1 = m->geom_bodyid[contact.geom1];
      const int body2 = m->geom_bodyid[contact.geom2];
      if (!character.IsCharacterBody(body1) ||
          !character.IsCharacterBody(body2) || -contact.dist <= 0.0 ||
          -contact.dist <= frame.self_penetration_m) {
        continue;
      }
      frame.self_penetration_m = -contact.dist;
      const char* name1 = mj_id2name(m, mjOBJ_GEOM, contact.geom1);
      const char* name2 = mj_id2name(m, mjOBJ_GEOM, contact.geom2);
      frame.self_contact =
          std::string(name1 ? name1 : "?") + "/" + (name2 ? name2 : "?");
    }
  }
}

}  // namespace

MotionFeasibility MeasureMotionFeasibility(const Character& character,
                                           const std::vector<Pose3D>& poses,
                                           double fps,
                                           const FeasibilityOptions& options) {
  // Outline: the clip as qpos rows; half-step velocities by differences of
  // consecutive rows, frame velocities and accelerations from those; per
  // frame, inverse dynamics with contacts and joint limits off, then each
  // hinge's torque against its limit where the floor cannot reach it, and
  // the external force against what a floor can push.
  options.Validate();
  const int num_frames = static_cast<int>(poses.size());
  if (num_frames < 3) {
    throw InputError("feasibility", "needs at least 3 frames of poses, got " +
                                        std::to_string(num_frames));
  }
  if (!(fps > 0.0)) throw InputError("feasibility", "fps must be > 0");
  MujocoModelPtr model(mj_copyModel(nullptr, character.model()));
  model->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_LIMIT;
  const mjModel* m = model.get();
  MujocoDataPtr data = MakeMujocoData(m);
  mjData* d = data.get();
  const int nv = m->nv;

  std::vector<std::vector<double>> qpos =
      PosesToQposAlongClip(character, poses);
  // Each frame's solution nearest the ranges, for the range check: the
  // continuous one above may sit on the other Euler branch.
  std::vector<double> nearest_range_qpos(m->nq);
  for (int t = 0; t < num_frames; ++t) {
    for (const FreeObject& object : character.free_objects()) {
      std::copy(m->qpos0 + object.qpos_address,
                m->qpos0 + object.qpos_address + 7,
                qpos[t].begin() + object.qpos_address);
    }
    for (double value : qpos[t]) {
      if (!std::isfinite(value)) {
        throw InputError("feasibility", "pose of frame " + std::to_string(t) +
                                            " is not finite");
      }
    }
  }

  // Velocity between frames t and t + 1 (tangent space: world linear and
  // local angular for the root, hinge rates).
  const double dt_s = 1.0 / fps;
  std::vector<std::vector<double>> half_step_qvel(num_frames - 1,
                                                  std::vector<double>(nv));
  for (int t = 0; t + 1 < num_frames; ++t) {
    mj_differentiatePos(m, half_step_qvel[t].data(), dt_s, qpos[t].data(),
                        qpos[t + 1].data());
  }

  MotionFeasibility result;
  result.num_frames = num_frames;
  result.range_tolerance_rad = options.range_tolerance_rad;
  result.reach_tolerance_m = options.reach_tolerance_m;
  result.penetration_tolerance_m = options.penetration_tolerance_m;
  result.fps = fps;
  double mass_kg = 0.0;
  for (int body : character.bodies()) mass_kg += m->body_mass[body];
  const double gravity_m_s2 =
      Eigen::Map<const Eigen::Vector3d>(m->opt.gravity).norm();
  result.body_weight_n = mass_kg * gravity_m_s2;
  for (const ActuatedHinge& hinge : character.hinges()) {
    HingeDemand demand;
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, hinge.actuator_id);
    demand.actuator =
        name ? name : "actuator " + std::to_string(hinge.actuator_id);
    demand.limit_nm = TorqueLimitNm(hinge, 1.0);
    result.hinges.push_back(demand);
  }
  const double tolerance_n =
      options.force_tolerance_body_weights * result.body_weight_n;
  const int root_dof = character.root_dof_address();

  for (int t = 0; t < num_frames; ++t) {
    // Central differences inside the clip; the nearest interior
    // acceleration at its ends.
    const int before = std::max(t - 1, 0);
    const int after = std::min(t, num_frames - 2);
    const int acc_at = std::clamp(t, 1, num_frames - 2);
    std::copy(qpos[t].begin(), qpos[t].end(), d->qpos);
    for (int i = 0; i < nv; ++i) {
      d->qvel[i] = 0.5 * (half_step_qvel[before][i] + half_step_qvel[after][i]);
      d->qacc[i] =
          (half_step_qvel[acc_at][i] - half_step_qvel[acc_at - 1][i]) / dt_s;
    }
    mj_inverse(m, d);

    FrameDemand frame;
    PoseToQpos(character, poses[t], nearest_range_qpos.data());
    for (size_t h = 0; h < character.hinges().size(); ++h) {
      const ActuatedHinge& hinge = character.hinges()[h];
      const double angle_rad = nearest_range_qpos[hinge.qpos_address];
      const double excess_rad = std::max({0.0, hinge.range_low_rad - angle_rad,
                                          angle_rad - hinge.range_high_rad});
      HingeDemand& demand = result.hinges[h];
      if (excess_rad > options.range_tolerance_rad)
        ++demand.frames_out_of_range;
      if (excess_rad > demand.peak_range_excess_rad) {
        demand.peak_range_excess_rad = excess_rad;
        demand.peak_range_frame = t;
      }
      if (excess_rad > frame.worst_range_excess_rad) {
        frame.worst_range_excess_rad = excess_rad;
        frame.worst_range_hinge = static_cast<int>(h);
      }
    }
    const std::vector<char> above_contact = BodiesAboveAContact(
        character, m, d, options.contact_height_m, &frame.touching);
    for (size_t h = 0; h < character.hinges().size(); ++h) {
      const ActuatedHinge& hinge = character.hinges()[h];
      if (above_contact[m->jnt_bodyid[hinge.joint_id]]) continue;
      HingeDemand& demand = result.hinges[h];
      // qfrc_inverse is what the actuator must add to the joint's damping;
      // under a limit on the whole PD, the damping is inside it.
      double torque_nm = d->qfrc_inverse[hinge.dof_address];
      if (options.torque_limit == TorqueLimit::kPd) {
        torque_nm -= hinge.kd_nm_s_per_rad * d->qvel[hinge.dof_address];
      }
      const double ratio =
          std::abs(torque_nm) / TorqueLimitNm(hinge, torque_nm);
      ++demand.frames_measured;
      if (ratio > 1.0) ++demand.frames_over_limit;
      demand.peak_nm = std::max(demand.peak_nm, std::abs(torque_nm));
      if (ratio > demand.peak_ratio) {
        demand.peak_ratio = ratio;
        demand.peak_frame = t;
      }
      if (ratio > frame.worst_torque_ratio) {
        frame.worst_torque_ratio = ratio;
        frame.worst_hinge = static_cast<int>(h);
      }
    }
    // The free joint's translational force is the sum of every external
    // force on the body, in the world frame.
    frame.external_force_n =
        Eigen::Map<const Eigen::Vector3d>(d->qfrc_inverse + root_dof);
    const double vertical_n = frame.external_force_n.z();
    const double horizontal_n = frame.external_force_n.head<2>().norm();
    if (!frame.touching) {
      frame.force_in_flight = frame.external_force_n.norm() > tolerance_n;
    } else {
      frame.pulls_floor = vertical_n < -tolerance_n;
      frame.slips = horizontal_n >
                    options.friction_coefficient * std::max(vertical_n, 0.0) +
                        tolerance_n;
    }
    result.frames.push_back(frame);
  }
  MeasureReach(character, poses, &result);
  MeasureSelfPenetration(character, qpos, &result);
  return result;
}

}  // namespace m2d
